// SlotTrajectory: one position per device. Readers that start at different times agree to the
// sample, a late reader starts where the puck is, re-basing moves every reader at once, and
// reports lost on the way still count (absolute counts).
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "SlotTrajectory.hpp"

using kf::MouseReport;
using kf::TrajectoryMode;
using kf::TrajectoryReconstructor;
using kf::sc::BlockClock;
using kf::sc::SlotTrajectory;

namespace {

constexpr int kBlock = 64;
constexpr double kSampleDurS = 1.0 / 48000.0;
constexpr double kCountMm = 0.021;

// A reader as FrictionMouseIn is one: copies the reference when it starts, then follows the
// entries and renders every block at audio rate.
struct Reader {
  TrajectoryMode mode;
  bool started = false;
  TrajectoryReconstructor trajectory;
  std::vector<float> x = std::vector<float>(kBlock), speed = std::vector<float>(kBlock);

  explicit Reader(TrajectoryMode m) : mode(m) {}
  void block(const SlotTrajectory& slot, const BlockClock& clock) {
    if (!started) {
      trajectory = slot.reference(mode);
      started = true;
    } else {
      kf::sc::addEntries(trajectory, slot.entries(), slot.numEntries());
    }
    trajectory.render(clock.startS, clock.sampleDurS, clock.numSamples, 0.0, x.data(), nullptr, speed.data(), nullptr);
  }
};

// Reports of a puck moving at varying speed: 125 Hz, counts from a sine speed profile.
struct Puck {
  int64_t xCounts = 0;
  int64_t yCounts = 0;
  double nextReportS = 0.008;
  int index = 0;
  // Reports due up to timeS (device time = audio time, lockstep).
  int poll(double untilS, MouseReport* out, int capacity) {
    int n = 0;
    while (nextReportS <= untilS && n < capacity) {
      const int dx = static_cast<int>(std::lround(40.0 * std::sin(index * 0.05)));
      xCounts += dx;
      yCounts += 1;
      MouseReport r;
      r.deviceTimeS = nextReportS;
      r.dxCounts = dx;
      r.dyCounts = 1;
      r.xCounts = xCounts;
      r.yCounts = yCounts;
      out[n++] = r;
      nextReportS += 0.008;
      ++index;
    }
    return n;
  }
};

BlockClock clockOf(int64_t block) { return BlockClock{block, block * kBlock * kSampleDurS, kSampleDurS, kBlock}; }

}  // namespace

TEST_CASE("two readers of one slot agree to the sample, whenever each started") {
  for (TrajectoryMode mode : {TrajectoryMode::Hold, TrajectoryMode::Linear, TrajectoryMode::Predictive}) {
    kf::DeviceSpec spec;
    SlotTrajectory slot;
    slot.reset(spec);
    Puck puck;
    Reader early(mode), late(mode);
    MouseReport reports[64];
    int compared = 0;
    for (int64_t b = 0; b < 3000; ++b) {
      const BlockClock clock = clockOf(b);
      const int n = puck.poll(clock.startS + kBlock * kSampleDurS, reports, 64);
      slot.takeBlock(clock, reports, n, /*lockstep=*/true, 0.0);
      early.block(slot, clock);
      if (b >= 1234) {  // 1.6 s later, in the middle of a movement
        late.block(slot, clock);
        for (int i = 0; i < kBlock; ++i) {
          REQUIRE(late.x[i] == early.x[i]);
          REQUIRE(late.speed[i] == early.speed[i]);
        }
        ++compared;
      }
    }
    CHECK(compared == 3000 - 1234);
    // And both sit on the device's absolute position once the last report has played out.
    CHECK(early.trajectory.reportedXMm() == Approx(puck.xCounts * kCountMm).margin(1e-9));
  }
}

TEST_CASE("a reader that starts late starts where the puck is, not at 0") {
  kf::DeviceSpec spec;
  SlotTrajectory slot;
  slot.reset(spec);
  Puck puck;
  Reader early(TrajectoryMode::Linear);
  MouseReport reports[64];
  for (int64_t b = 0; b < 1000; ++b) {
    const BlockClock clock = clockOf(b);
    slot.takeBlock(clock, reports, puck.poll(clock.startS + kBlock * kSampleDurS, reports, 64), true, 0.0);
    early.block(slot, clock);
  }
  REQUIRE(std::abs(early.x[kBlock - 1]) > 10.0);  // the puck has moved away from 0
  const BlockClock clock = clockOf(1000);
  slot.takeBlock(clock, reports, puck.poll(clock.startS + kBlock * kSampleDurS, reports, 64), true, 0.0);
  Reader late(TrajectoryMode::Linear);
  late.block(slot, clock);
  early.block(slot, clock);
  CHECK(late.x[0] == early.x[0]);
  CHECK(late.x[kBlock - 1] == early.x[kBlock - 1]);
}

TEST_CASE("re-basing (kfZero) moves every reader at the same block by the same step") {
  kf::DeviceSpec spec;
  SlotTrajectory slot;
  slot.reset(spec);
  Puck puck;
  Reader a(TrajectoryMode::Linear), b(TrajectoryMode::Predictive);
  MouseReport reports[64];
  double before = 0.0;
  for (int64_t blk = 0; blk < 1500; ++blk) {
    const BlockClock clock = clockOf(blk);
    if (blk == 900) {
      before = slot.reportedXMm();
      slot.requestPosition(0.0, 5.0);
    }
    slot.takeBlock(clock, reports, puck.poll(clock.startS + kBlock * kSampleDurS, reports, 64), true, 0.0);
    if (blk == 900) {
      // The latest reported position (before this block's reports) became (0, 5): the block's
      // first entry is the shift, then the reports move on from there.
      REQUIRE(slot.numEntries() >= 1);
      CHECK(slot.entries()[0].isShift);
      CHECK(slot.entries()[0].dxMm == Approx(-before));
    }
    const float ax = a.x[kBlock - 1];
    a.block(slot, clock);
    b.block(slot, clock);
    if (blk == 900) CHECK(std::abs(a.x[0] - (ax - before)) < 0.5);  // stepped by -before, not drifted
  }
  // After re-basing, the absolute position is the counts since the zero plus the new origin.
  CHECK(slot.reportedXMm() == Approx(puck.xCounts * kCountMm - before).margin(1e-9));
  CHECK(a.trajectory.reportedXMm() == Approx(slot.reportedXMm()).margin(1e-9));
  CHECK(b.trajectory.reportedYMm() == Approx(slot.reportedYMm()).margin(1e-9));
}

TEST_CASE("reports lost before the slot (a full queue) still count, and a gap restarts at the position") {
  kf::DeviceSpec spec;
  SlotTrajectory slot;
  slot.reset(spec);
  Puck puck;
  Reader r(TrajectoryMode::Linear);
  MouseReport reports[64];
  for (int64_t b = 0; b < 400; ++b) {
    const BlockClock clock = clockOf(b);
    int n = puck.poll(clock.startS + kBlock * kSampleDurS, reports, 64);
    if (b % 10 == 3) n = 0;  // these reports are lost; later ones carry their counts
    slot.takeBlock(clock, reports, n, true, 0.0);
    r.block(slot, clock);
  }
  // Blocks 400..599: nobody looks. Then a new reader and the old one come back.
  for (int64_t b = 400; b < 600; ++b) puck.poll(clockOf(b).startS + kBlock * kSampleDurS, reports, 64);
  const BlockClock clock = clockOf(600);
  const int n = puck.poll(clock.startS + kBlock * kSampleDurS, reports, 64);
  slot.takeBlock(clock, reports, n, true, 0.0);
  Reader fresh(TrajectoryMode::Linear);
  fresh.block(slot, clock);
  CHECK(slot.numEntries() == 0);  // the backlog counts for its position only
  CHECK(fresh.x[0] == Approx(puck.xCounts * kCountMm).margin(1e-4));
}

TEST_CASE("realtime: one clock mapping for the slot, so readers agree under arrival jitter") {
  kf::DeviceSpec spec;
  SlotTrajectory slot;
  slot.reset(spec);
  Puck puck;
  Reader early(TrajectoryMode::Predictive), late(TrajectoryMode::Predictive);
  MouseReport reports[64];
  uint32_t seed = 12345;
  for (int64_t b = 0; b < 2000; ++b) {
    const BlockClock clock = clockOf(b);
    // Device clock 0.3 s behind audio, reports arriving one block late now and then.
    seed = seed * 1664525u + 1013904223u;
    const double lagS = (seed >> 28) == 0 ? kBlock * kSampleDurS : 0.0;
    int n = puck.poll(clock.startS - 0.3 - lagS, reports, 64);
    slot.takeBlock(clock, reports, n, /*lockstep=*/false, 0.0);
    early.block(slot, clock);
    if (b >= 777) {
      late.block(slot, clock);
      for (int i = 0; i < kBlock; ++i) REQUIRE(late.x[i] == early.x[i]);
    }
  }
}

TEST_CASE("realtime: re-basing reaches every reader at the next block, after a stall of the audio thread too") {
  // After a stall the clock mapper spreads the catch-up, so reports are mapped ahead of the
  // audio clock and wait in the readers; a re-basing queued behind them came 0.14 s late after
  // a stall of 0.3 s (the realtime test saw 0.16 s without realtime scheduling).
  kf::DeviceSpec spec;
  SlotTrajectory slot;
  slot.reset(spec);
  Reader a(TrajectoryMode::Linear), b(TrajectoryMode::Hold);
  std::vector<MouseReport> reports;
  const double blockS = kBlock * kSampleDurS;
  double deviceS = 0.0, nextReportS = 0.008;
  int64_t xCounts = 0, block = 0;
  bool requested = false;
  while (deviceS < 3.0) {  // and then until the readers have caught up
    deviceS += blockS;
    if (deviceS > 1.0 && deviceS < 1.3) continue;  // the audio thread stalls; the mouse goes on
    reports.clear();
    for (; nextReportS <= deviceS; nextReportS += 0.008) {
      MouseReport r;
      xCounts += 12;  // 31.5 mm/s
      r.deviceTimeS = nextReportS;
      r.dxCounts = 12;
      r.xCounts = xCounts;
      reports.push_back(r);
    }
    const BlockClock clock = clockOf(block++);
    const bool request = !requested && deviceS > 1.32;
    if (request) slot.requestPosition(100.0, 0.0);
    slot.takeBlock(clock, reports.data(), static_cast<int>(reports.size()), /*lockstep=*/false, 0.0);
    const float before = a.x[kBlock - 1];
    a.block(slot, clock);
    b.block(slot, clock);
    if (request) {
      requested = true;
      REQUIRE(a.trajectory.pendingReports() > 10);  // the readers are behind the latest report
      // Stepped by the shift at this block (by 100 - 41 mm), not after the reports waiting.
      CHECK(a.x[0] - before > 50.0);
      CHECK(b.x[0] > 50.0);
    }
  }
  REQUIRE(requested);
  CHECK(a.trajectory.reportedXMm() == Approx(slot.reportedXMm()).margin(1e-9));
  CHECK(a.x[kBlock - 1] == Approx(slot.reportedXMm()).margin(0.5));
}

TEST_CASE("the slot turns the mouse's counts into the surface's mm with the spec's sizes, swap and signs") {
  // A mouse turned a quarter in the puck (mouse +y is surface +x, mouse +x is surface -y),
  // with different count sizes along the surface's two axes (a mouse profile's).
  kf::DeviceSpec spec;
  spec.countMm = 0.02;
  spec.countMmY = 0.03;
  spec.swapXY = 1;
  spec.signY = -1;
  SlotTrajectory slot;
  slot.reset(spec);
  MouseReport reports[2];
  reports[0].deviceTimeS = 0.0005, reports[0].xCounts = 100, reports[0].yCounts = 50;
  reports[1].deviceTimeS = 0.0010, reports[1].xCounts = 110, reports[1].yCounts = 40;
  slot.takeBlock(clockOf(0), reports, 0, true, 0.0);  // the first look: starts at 0
  slot.takeBlock(clockOf(1), reports, 2, true, 0.0);
  CHECK(slot.reportedXMm() == Approx(40 * 0.02));
  CHECK(slot.reportedYMm() == Approx(-110 * 0.03));
  REQUIRE(slot.numEntries() == 2);
  CHECK(slot.entries()[1].dxMm == Approx(-10 * 0.02));  // the step of the second report
  CHECK(slot.entries()[1].dyMm == Approx(-10 * 0.03));
}

TEST_CASE("the buttons of a block: down in any of its reports, else the last report's") {
  kf::DeviceSpec spec;
  spec.countMm = kCountMm;
  SlotTrajectory slot;
  slot.reset(spec);
  auto report = [](double timeS, uint32_t buttons) {
    MouseReport r;
    r.deviceTimeS = timeS;
    r.buttons = buttons;
    return r;
  };
  BlockClock clock;
  auto take = [&](int64_t block, std::vector<MouseReport> reports) {
    clock.block = block;
    clock.startS = block * kBlock * kSampleDurS;
    slot.takeBlock(clock, reports.data(), static_cast<int>(reports.size()), true, 0.0);
    return slot.buttons();
  };
  CHECK(take(0, {}) == 0u);
  CHECK(take(1, {report(0.0015, 1)}) == 1u);                     // left down
  CHECK(take(2, {}) == 1u);                                      // held: no report, the last one's
  CHECK(take(3, {report(0.004, 0)}) == 0u);                      // released
  CHECK(take(4, {report(0.0055, 2), report(0.0056, 0)}) == 2u);  // a right click within one block
  CHECK(take(5, {}) == 0u);                                      // ... released by the block's last report
  slot.reset(spec);
  CHECK(slot.buttons() == 0u);
}
