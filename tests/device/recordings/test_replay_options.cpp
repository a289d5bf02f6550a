// ReplayBackend for live use: start time, skipping the idle lead-in, loop and rate. Without
// options the file plays exactly as recorded.
#include <catch2/catch.hpp>
#include <vector>

#include "recordings/ReplayBackend.hpp"

using kf::MouseReport;
using kf::ReplayBackend;
using kf::ReplayOptions;
using kf::TimedReport;

namespace {

// 2 s of idle reports (no counts), then 1 s moving +3 counts per report, at 125 Hz.
std::vector<TimedReport> recording() {
  std::vector<TimedReport> reports;
  for (int i = 1; i <= 375; ++i) {
    TimedReport r;
    r.hostTimeS = i * 0.008;
    r.report.deviceTimeS = i * 0.008 + 0.0001;  // the device's own clock, a little off
    r.report.dxCounts = i > 250 ? 3 : 0;
    reports.push_back(r);
  }
  return reports;
}

// All reports released up to untilS: (count, summed dx, last device time).
struct Polled {
  int count = 0;
  long dx = 0;
  double lastDeviceS = 0.0;
};

Polled pollUntil(ReplayBackend& replay, double untilS) {
  Polled p;
  MouseReport buffer[64];
  int n = 0;
  while ((n = replay.pollReports(untilS, buffer, 64)) > 0)
    for (int i = 0; i < n; ++i) {
      ++p.count;
      p.dx += buffer[i].dxCounts;
      p.lastDeviceS = buffer[i].deviceTimeS;
    }
  return p;
}

}  // namespace

TEST_CASE("replay without options plays the file as recorded") {
  ReplayBackend replay(recording());
  const Polled p = pollUntil(replay, 1.0);
  CHECK(p.count == 125);
  CHECK(p.dx == 0);
  CHECK(p.lastDeviceS == Approx(1.0001));
  CHECK(pollUntil(replay, 10.0).dx == 125 * 3);
  CHECK(replay.isFinished());
}

TEST_CASE("skipIdle starts one interval before the first movement") {
  ReplayOptions options;
  options.skipIdle = true;
  ReplayBackend replay(recording(), options);
  CHECK(replay.startFileS() == Approx(2.008 - 0.008));
  const Polled p = pollUntil(replay, 0.1);  // the first 100 ms already move
  CHECK(p.dx > 0);
  CHECK(pollUntil(replay, 1.5).dx + p.dx == 125 * 3);
}

TEST_CASE("startS starts at a file time, rate plays faster on the same path") {
  ReplayOptions options;
  options.startS = 1.5;
  options.rate = 2.0;
  ReplayBackend replay(recording(), options);
  // 1.5 s of file (from 1.5 to 3.0) takes 0.75 s.
  const Polled half = pollUntil(replay, 0.25);  // file 1.5 .. 2.0: still idle
  CHECK(half.dx == 0);
  const Polled rest = pollUntil(replay, 0.8);
  CHECK(rest.dx == 125 * 3);
  CHECK(rest.lastDeviceS == Approx((3.0001 - 1.5) / 2.0));
  CHECK(replay.isFinished());
}

TEST_CASE("loop plays the recording again and the counts keep adding up") {
  ReplayOptions options;
  options.skipIdle = true;
  options.loop = true;
  ReplayBackend replay(recording(), options);
  const double periodS = 3.0 - 2.0 + 0.008;  // one pass: file 2.0 .. 3.0 and one interval
  const Polled p = pollUntil(replay, 3 * periodS + 0.004);
  CHECK(p.dx == 3 * 125 * 3);
  CHECK_FALSE(replay.isFinished());
  // Device times keep increasing across passes.
  // Device times keep increasing across passes: the 4th pass has begun (its first report, at
  // file time 2.0, is idle).
  CHECK(p.lastDeviceS == Approx(3 * periodS + 0.0001).margin(1e-9));
}

TEST_CASE("replay settings by name are checked") {
  ReplayOptions options;
  CHECK(options.applyOverride("rate", 0.5));
  CHECK(options.applyOverride("loop", 1));
  CHECK(options.applyOverride("startS", 2));
  CHECK(options.applyOverride("skipIdle", 0));
  CHECK_FALSE(options.applyOverride("rate", 0));
  CHECK_FALSE(options.applyOverride("rate", -1));
  CHECK_FALSE(options.applyOverride("loop", 2));
  CHECK_FALSE(options.applyOverride("startS", -1));
  CHECK_FALSE(options.applyOverride("countMm", 1));
  CHECK(options.rate == 0.5);
  CHECK(options.loop);
}
