#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <thread>

#include "DeviceFactory.hpp"
#include "core/Device.hpp"
#include "recordings/ReplayBackend.hpp"
#include "sim/SimDevice.hpp"

using namespace kf;
using namespace std::chrono_literals;

TEST_CASE("realtime device thread: 125 Hz reports, frames reach the magnet, telemetry", "[thread][wallclock]") {
  const DeviceSpec spec;
  auto sim = std::make_shared<SimDevice>(spec, SimParams{}, HandScript::speeds({{100.0, 5.0}}));
  auto sink = std::make_shared<CountingForceSink>();
  Device device(spec, sim, sink, false);
  device.start();
  CHECK_FALSE(device.isLockstep());

  std::atomic<bool> stop{false};
  std::atomic<int> pushed{0};
  std::thread audio([&] {  // stands in for FrictionOut: one frame per ms
    // Realtime where allowed, below the device thread, as scsynth's audio thread is: at normal
    // priority two CPU hogs hold it up past the 10 ms watchdog.
    scheduleThisThread("audio", {0, kFallbackPriority - 1});
    int frame = 0;
    auto next = std::chrono::steady_clock::now();
    while (!stop.load()) {
      next += 1ms;
      std::this_thread::sleep_until(next);
      if (device.pushForceFrame({frame * 0.001, 0.3f})) pushed.fetch_add(1);
      ++frame;
    }
  });
  std::vector<MouseReport> reports;
  MouseReport buffer[32];
  const auto popAll = [&] {
    int n;
    while ((n = device.popReports(buffer, 32)) > 0) reports.insert(reports.end(), buffer, buffer + n);
  };
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < 300ms) {
    popAll();
    std::this_thread::sleep_for(2ms);
  }
  // And what came while this thread last slept: at normal priority it can wake long after the
  // window's end (beside three realtime servers, a fresh clone's libc++ suite kept 20 reports,
  // 160 ms of them, and left the rest in the queue).
  popAll();
  const double windowS = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stop = true;
  audio.join();
  // Let the thread take the last frames (bounded wait, for loaded machines).
  const auto waitStart = std::chrono::steady_clock::now();
  while (device.telemetry().frames + device.telemetry().skippedFrames < static_cast<uint64_t>(pushed.load()) &&
         std::chrono::steady_clock::now() - waitStart < 2s)
    std::this_thread::sleep_for(1ms);
  const TelemetrySnapshot telemetry = device.telemetry();
  device.close();

  // ~0.3 s at 125 Hz (37.5 reports); generous bounds for a loaded machine. The window is longer
  // when this thread woke late: the upper bound grows by its reports (one each 8 ms).
  INFO("reports popped " << reports.size() << " in " << windowS << " s; the device's: " << telemetry.reports
                         << ", its missed deadlines " << telemetry.missedDeadlines);
  CHECK(reports.size() >= 30);
  CHECK(reports.size() <= 45 + static_cast<size_t>((windowS - 0.3) / 0.008));
  CHECK(telemetry.reports >= reports.size());
  CHECK(telemetry.reportIntervalMeanS == Approx(0.008).epsilon(1e-6));
  CHECK(telemetry.reportIntervalJitterS < 1e-6);
  for (size_t i = 1; i < reports.size(); ++i)
    CHECK(reports[i].deviceTimeS - reports[i - 1].deviceTimeS == Approx(0.008));
  CHECK(pushed.load() > 150);
  // Every frame reached the magnet but those a pump that missed its deadlines skipped as stale: a
  // pump that missed k skips at most k + 1 <= 2k, so at most twice the missed deadlines in all
  // (test_frame_timing.cpp; a fresh clone's ASan run saw 16 skipped for 15 missed).
  CHECK(telemetry.frames + telemetry.skippedFrames == static_cast<uint64_t>(pushed.load()));
  CHECK(telemetry.skippedFrames <= 2 * telemetry.missedDeadlines);
  CHECK(sink->commands() == telemetry.frames);
  CHECK(sink->lastForceN() == 0.3f);
  CHECK(telemetry.watchdogTrips == 0);
  CHECK(telemetry.reportQueueOverflows == 0);
  CHECK(telemetry.frameQueueOverflows == 0);
  CHECK(telemetry.pumps > 100);
  CHECK(sink->driveOffs() == 1);
  // In realtime the device thread is the only pumper: calls from outside do nothing.
  const uint64_t pumps = device.telemetry().pumps;
  device.pump(1000.0);
  CHECK(device.telemetry().pumps == pumps);
}

TEST_CASE("lockstep pump: same code path, idempotent for past times", "[thread]") {
  const DeviceSpec spec;
  auto device = openSimDevice(spec, SimParams{}, HandScript::speeds({{100.0, 2.0}}), true);
  REQUIRE(device);
  CHECK(device->isLockstep());
  MouseReport buffer[16];
  device->pump(0.1);
  CHECK(device->popReports(buffer, 16) == 12);  // 8, 16, ..., 96 ms
  device->pump(0.1);                            // a second UGen in the same block
  device->pump(0.05);                           // the past
  CHECK(device->popReports(buffer, 16) == 0);
  CHECK(device->telemetry().pumps == 1);
  device->pump(0.104);
  CHECK(device->popReports(buffer, 16) == 1);
  CHECK(buffer[0].deviceTimeS == Approx(0.104));
}

TEST_CASE("report queue overflow is counted, not waited on", "[thread]") {
  const DeviceSpec spec;
  DeviceOptions options;
  options.reportQueueCapacity = 10;
  auto device = openSimDevice(spec, SimParams{}, HandScript::none(), true, nullptr, options);
  REQUIRE(device);
  device->pump(1.0);  // 125 reports, nobody pops
  const TelemetrySnapshot telemetry = device->telemetry();
  CHECK(telemetry.reports == 125);
  CHECK(telemetry.reportQueueOverflows == 115);
  MouseReport buffer[32];
  CHECK(device->popReports(buffer, 32) == 10);
  CHECK(buffer[0].deviceTimeS == Approx(0.008));  // the oldest were kept
}

TEST_CASE("factory rejects unusable specs and scripts", "[thread]") {
  DeviceSpec spec;
  spec.minForceN = 2.0;
  std::string error;
  CHECK_FALSE(openSimDevice(spec, SimParams{}, HandScript::none(), true, &error));
  CHECK(error.find("spec") != std::string::npos);
  CHECK_FALSE(openSimDevice(DeviceSpec{}, SimParams{}, HandScript::path({{1.0, 0.0}, {0.5, 3.0}}), true, &error));
  CHECK(error.find("hand") != std::string::npos);
}
