// The fail-safe force path (ForceSafety, in Device): each rule, and when the magnet went off.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <memory>

#include "ForcePathSupport.hpp"
#include "core/Device.hpp"
#include "core/force/ForceSafety.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;
using kf::test::TimelineSink;

namespace {
std::shared_ptr<ReplayBackend> noMouse() { return std::make_shared<ReplayBackend>(std::vector<TimedReport>{}); }

CalibrationTable table(std::vector<CalibrationPoint> points) {
  CalibrationTable out;
  std::string error;
  REQUIRE(CalibrationTable::fromPoints(std::move(points), out, error));
  return out;
}
}  // namespace

TEST_CASE("force path order: non-finite, clamp, slew, calibration, drive limit, heat", "[safety]") {
  DeviceSpec spec;
  spec.maxForceSlewNPerS = 200.0;  // 0.2 N per 1 ms frame
  ForceSafety safety(spec);
  // Calibration: quadratic-ish coil, 0.14 N at rest, 1.4 N at full drive.
  safety.setCalibration(table({{0.0, 0.14}, {0.5, 0.5}, {1.0, 1.4}}));
  double t = 0.0;
  auto frame = [&](float forceN) {
    t += 0.001;
    return safety.applyFrame({t, forceN}, t);
  };

  // 1: NaN is the minimum, which is drive 0.
  CHECK(frame(std::numeric_limits<float>::quiet_NaN()) == 0.14f);
  CHECK(safety.driveLevel() == 0.0f);
  // 2, 3: 5 N is clamped to 1.4 N, reached in 0.2 N steps.
  CHECK(frame(5.0f) == Approx(0.34));
  CHECK(frame(5.0f) == Approx(0.54));
  // 4: 0.5 N is drive 0.5 exactly (a table point); 0.54 N is between the points.
  CHECK(safety.driveLevel() == Approx(0.5 + 0.04 / 0.9 * 0.5));
  for (int i = 0; i < 10; ++i) frame(5.0f);
  CHECK(safety.commandedForceN() == 1.4f);
  CHECK(safety.driveLevel() == 1.0f);
  CHECK(safety.driveLimitedFrames() == 0);
}

TEST_CASE("the hard drive limit lowers the drive and the commanded force shows it", "[safety]") {
  DeviceSpec spec;
  spec.maxDriveLevel = 0.5;
  ForceSafety safety(spec);  // linear: 0.14 + 1.26 * drive
  CHECK(safety.applyFrame({0.001, 1.4f}, 0.001) == Approx(0.14 + 0.63));
  CHECK(safety.driveLevel() == 0.5f);
  CHECK(safety.driveLimitedFrames() == 1);
  CHECK(safety.applyFrame({0.002, 0.5f}, 0.002) == 0.5f);  // below the limit: unchanged
  CHECK(safety.driveLimitedFrames() == 1);
}

TEST_CASE("the heat estimate derates a long full drive smoothly, and recovers when cool", "[safety]") {
  DeviceSpec spec;
  spec.heatTimeConstantS = 2.0;
  spec.heatRatedDuty = 0.25;  // the coil takes drive 0.5 for ever
  ForceSafety safety(spec);
  double t = 0.0;
  float previousDrive = 0.0f;
  double firstDerateS = -1.0;
  int reversals = 0;
  float lastStep = 0.0f;
  for (int i = 0; i < 20000; ++i) {  // 20 s of full force
    t += 0.001;
    safety.applyFrame({t, 1.4f}, t);
    const float drive = safety.driveLevel();
    if (drive < 1.0f && firstDerateS < 0.0) firstDerateS = t;
    const float step = drive - previousDrive;
    if (i > 1 && step * lastStep < 0.0f && std::abs(step) > 1e-4f) ++reversals;
    if (step != 0.0f) lastStep = step;
    previousDrive = drive;
  }
  // heat = 1 - exp(-t/2) reaches 0.9 * 0.25 after 2 * ln(1/0.775) = 0.51 s.
  CHECK(firstDerateS == Approx(0.51).margin(0.01));
  // Steady state: drive^2 stays within the rated heat band; the drive settles, no chatter.
  CHECK(safety.heat() <= 0.25 + 1e-3);
  CHECK(safety.heat() >= 0.9 * 0.25 - 1e-3);
  CHECK(safety.driveLevel() >= 0.5f - 1e-3f);
  CHECK(safety.driveLevel() < 0.55f);
  CHECK(reversals <= 2);
  CHECK(safety.commandedForceN() < 1.4f * 0.6f);
  // Off for 10 s (a gap between frames cools the coil): full drive again.
  t += 0.001;
  safety.applyFrame({t, 0.14f}, t);
  CHECK(safety.driveLevel() == 0.0f);
  t += 10.0;
  safety.applyFrame({t, 0.14f}, t);
  t += 0.001;
  safety.applyFrame({t, 1.4f}, t);
  CHECK(safety.driveLevel() == 1.0f);
}

TEST_CASE("a calibration whose range is narrower than the device's is honest about it", "[safety]") {
  ForceSafety safety{DeviceSpec{}};
  safety.setCalibration(table({{0.0, 0.2}, {1.0, 1.0}}));
  CHECK(safety.applyFrame({0.001, 1.4f}, 0.001) == 1.0f);
  CHECK(safety.driveLevel() == 1.0f);
  CHECK(safety.applyFrame({0.002, 0.14f}, 0.002) == 0.2f);
  CHECK(safety.driveLevel() == 0.0f);
}

TEST_CASE("lockstep: the magnet goes off 10 ms after the last frame, at close at once", "[safety]") {
  const DeviceSpec spec;
  auto sink = std::make_shared<TimelineSink>();
  Device device(spec, noMouse(), sink, true);
  double nowS = 0.0;
  sink->setClock([&] { return nowS; });
  device.start();
  device.pump(nowS = 0.001);
  for (int i = 1; i <= 100; ++i) {  // 100 ms of frames, pumped every 1 ms
    device.pushForceFrame({i * 0.001, 1.0f});
    device.pump(nowS = (i + 1) * 0.001);
  }
  for (int i = 0; i < 50; ++i) device.pump(nowS += 0.0005);  // frames stop; pumps every 0.5 ms
  const auto offs = sink->offTimes();
  REQUIRE(offs.size() == 1);
  // The last frame went in at 0.100 s (its push, one pump after 0.1): off 10 ms later.
  CHECK(offs[0] - 0.100 == Approx(0.010).margin(0.0006));
  CHECK(device.commandedForceN() == static_cast<float>(spec.minForceN));
  // Frames again (pumped on as a render does), then close: off at the close.
  device.pump(nowS = 0.2);
  device.pushForceFrame({0.2, 1.0f});
  device.pump(nowS = 0.2005);
  CHECK(device.commandedForceN() == 1.0f);
  device.close();
  CHECK(sink->offTimes().size() == 2);
  CHECK(sink->offTimes().back() == 0.2005);
  CHECK(device.commandedForceN() == static_cast<float>(spec.minForceN));
}

TEST_CASE("lockstep: a pushed frame is commanded at once and FrictionOut can read it", "[safety]") {
  DeviceSpec spec;
  spec.maxForceSlewNPerS = 100.0;  // 0.1 N per frame
  auto sink = std::make_shared<TimelineSink>();
  Device device(spec, noMouse(), sink, true);
  device.start();
  device.pump(0.001);
  device.pushForceFrame({0.000, 1.4f});
  CHECK(device.commandedForceN() == Approx(0.24));  // slewed, not the requested 1.4
  REQUIRE(sink->commands().size() == 1);
  CHECK(sink->commands()[0].timeS == 0.0);
  CHECK(sink->commands()[0].drive == Approx(0.1 / 1.26));
}
