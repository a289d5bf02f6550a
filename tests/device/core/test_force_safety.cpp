#include <catch2/catch.hpp>
#include <limits>
#include <memory>

#include "core/Device.hpp"
#include "core/force/ForceSafety.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;

TEST_CASE("NaN and Inf become the minimum force", "[safety]") {
  const DeviceSpec spec;
  ForceSafety safety(spec);
  safety.applyFrame({0.000, 0.3f}, 0.000);
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                    -std::numeric_limits<float>::infinity()}) {
    safety.applyFrame({0.001, 0.5f}, 0.001);
    CHECK(safety.applyFrame({0.002, bad}, 0.002) == static_cast<float>(spec.minForceN));
  }
}

TEST_CASE("forces are clamped to the device range", "[safety]") {
  const DeviceSpec spec;
  ForceSafety safety(spec);
  double timeS = 0.0;
  float commanded = 0.0f;
  for (int i = 0; i < 10; ++i) {
    timeS += 0.001;
    commanded = safety.applyFrame({timeS, 5.0f}, timeS);
  }
  CHECK(commanded == static_cast<float>(spec.maxForceN));
  timeS += 0.001;
  CHECK(safety.applyFrame({timeS, -1.0f}, timeS) == static_cast<float>(spec.minForceN));
  timeS += 0.001;
  CHECK(safety.applyFrame({timeS, 0.7f}, timeS) == 0.7f);
}

TEST_CASE("force changes are slew limited", "[safety]") {
  DeviceSpec spec;
  spec.maxForceSlewNPerS = 100.0;  // 0.1 N per 1 ms frame
  ForceSafety safety(spec);
  double timeS = 0.0;
  float previous = static_cast<float>(spec.minForceN);
  int frames = 0;
  for (; frames < 100; ++frames) {
    timeS += 0.001;
    const float commanded = safety.applyFrame({timeS, 1.4f}, timeS);
    CHECK(commanded - previous <= 0.1f + 1e-6f);
    previous = commanded;
    if (commanded == 1.4f) break;
  }
  CHECK(frames + 1 == 13);  // 1.26 N at 0.1 N per frame
  // Down as well; a longer gap between frames allows a larger step.
  timeS += 0.001;
  CHECK(safety.applyFrame({timeS, 0.14f}, timeS) == Approx(1.3f));
  timeS += 0.005;
  CHECK(safety.applyFrame({timeS, 0.14f}, timeS) == Approx(0.8f));
  // The default slew (2000 N/s) passes a full-range jump within one frame.
  ForceSafety fast{DeviceSpec{}};
  CHECK(fast.applyFrame({0.001, 1.4f}, 0.001) == Approx(1.4f));
}

TEST_CASE("watchdog drives the magnet off when frames stop", "[safety]") {
  const DeviceSpec spec;  // watchdog 10 ms
  auto sink = std::make_shared<CountingForceSink>();
  auto mouse = std::make_shared<ReplayBackend>(std::vector<TimedReport>{});
  Device device(spec, mouse, sink, true);
  device.start();
  REQUIRE(device.pushForceFrame({0.001, 1.0f}));
  device.pump(0.002);
  CHECK(sink->commands() == 1);
  CHECK(sink->lastForceN() == 1.0f);
  device.pump(0.002 + 0.009);
  CHECK(sink->driveOffs() == 0);
  CHECK(device.telemetry().watchdogTrips == 0);
  device.pump(0.002 + 0.0101);
  CHECK(sink->driveOffs() == 1);
  CHECK(device.telemetry().watchdogTrips == 1);
  CHECK(device.telemetry().lastCommandedForceN == static_cast<float>(spec.minForceN));
  device.pump(0.2);  // tripped once, not again
  CHECK(sink->driveOffs() == 1);
  // Frames re-arm it; the force slews up from off again.
  REQUIRE(device.pushForceFrame({0.201, 0.5f}));
  device.pump(0.202);
  CHECK(sink->lastForceN() == 0.5f);
  device.pump(0.3);
  CHECK(device.telemetry().watchdogTrips == 2);
  CHECK(sink->driveOffs() == 2);
}

TEST_CASE("closing drives the magnet off, also from the destructor", "[safety]") {
  const DeviceSpec spec;
  auto sink = std::make_shared<CountingForceSink>();
  {
    Device device(spec, std::make_shared<ReplayBackend>(std::vector<TimedReport>{}), sink, true);
    device.start();
    device.pushForceFrame({0.001, 1.2f});
    device.pump(0.001);
    CHECK(device.telemetry().lastCommandedForceN == 1.2f);
    device.close();
    CHECK(sink->driveOffs() == 1);
    CHECK(device.telemetry().lastCommandedForceN == static_cast<float>(spec.minForceN));
    device.close();  // idempotent
    CHECK(sink->driveOffs() == 1);
    device.pushForceFrame({0.002, 1.2f});
    device.pump(0.01);  // closed: nothing reaches the magnet
    CHECK(sink->commands() == 1);
  }
  auto sink2 = std::make_shared<CountingForceSink>();
  {
    Device device(spec, std::make_shared<ReplayBackend>(std::vector<TimedReport>{}), sink2, false);
    device.start();
  }
  CHECK(sink2->driveOffs() == 1);
}
