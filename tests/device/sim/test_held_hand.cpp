// A hand held until released (SimParams::handHeld, kfSimRelease): the puck rests while it is
// held, and once released the scene is the free hand's, shifted to the release.
#include <algorithm>
#include <catch2/catch.hpp>
#include <string>

#include "sim/SimDevice.hpp"

using namespace kf;

namespace {

SimParams held() {
  SimParams params;
  params.handHeld = 1.0;
  return params;
}

ExploreSettings participant() {  // as the study's simulated participants explore
  ExploreSettings s;
  s.fromMm = 0.0;
  s.toMm = 40.0;
  s.slowMmPerS = 20.0;
  s.fastMmPerS = 150.0;
  s.tiers = 3.0;
  s.tierS = 0.5;
  s.maxPushN = 1.2;
  s.gainNSPerM = 10.0;
  s.adaptS = 0.8;
  return s;
}

// The free device's positions every 10 ms for durationS, and the held one's from its release at
// releaseS on; both with the magnet at 0.3 N from the hand's start (as a condition's pilot).
void compareShifted(const HandScript& hand, double releaseS, double durationS) {
  SimDevice free(DeviceSpec{}, SimParams{}, hand);
  SimDevice late(DeviceSpec{}, held(), hand);
  late.advanceTo(releaseS);
  CHECK(late.handIsHeld());
  CHECK(late.positionMm() == 0.0);
  CHECK(late.handForceN() == 0.0);
  late.releaseHand();
  free.commandForce(0.0, 0.3f);
  late.commandForce(releaseS, 0.3f);
  double furthestMm = 0.0;
  for (int tenMs = 1; tenMs <= static_cast<int>(durationS * 100.0); ++tenMs) {
    const double t = tenMs * 0.01;
    free.advanceTo(t);
    late.advanceTo(releaseS + t);
    // The two times differ only in the sum's rounding (1e-16 s of 1e-4 s steps): the same steps.
    REQUIRE(late.positionMm() == Approx(free.positionMm()).margin(1e-9));
    furthestMm = std::max(furthestMm, free.positionMm());
  }
  CHECK_FALSE(late.handIsHeld());
  CHECK(furthestMm > 5.0);  // the scene moved the puck: the comparison is not of two rests
}

}  // namespace

TEST_CASE("a held hand leaves the puck at rest and pushes nothing until released", "[sim]") {
  SimDevice sim(DeviceSpec{}, held(), HandScript::speeds({{100.0, 2.0}}));
  MouseReport reports[512];
  const int count = sim.pollReports(1.0, reports, 512);
  CHECK(count == 125);  // a resting mouse still reports, at 125 Hz
  for (int i = 0; i < count; ++i) CHECK(reports[i].dxCounts == 0);
  CHECK(sim.positionMm() == 0.0);
  CHECK(sim.handForceN() == 0.0);
  sim.releaseHand();
  sim.advanceTo(1.5);
  CHECK(sim.positionMm() > 30.0);  // 0.5 s at up to 100 mm/s, after the hand's lag
}

TEST_CASE("a released scripted hand moves the puck as a free one, from the release", "[sim]") {
  compareShifted(HandScript::speeds({{100.0, 0.6}, {-60.0, 0.6}}), 0.7341, 1.5);
}

TEST_CASE("a released exploring participant explores as a free one, from the release", "[sim]") {
  // Its speed steps (tierS) and its learning count from the release, not from the open.
  compareShifted(HandScript::exploring(participant()), 1.25, 2.0);
}

TEST_CASE("releasing a hand that is not held changes nothing", "[sim]") {
  SimDevice a(DeviceSpec{}, SimParams{}, HandScript::speeds({{80.0, 1.0}}));
  SimDevice b(DeviceSpec{}, SimParams{}, HandScript::speeds({{80.0, 1.0}}));
  a.advanceTo(0.3);
  b.advanceTo(0.3);
  b.releaseHand();
  a.advanceTo(0.9);
  b.advanceTo(0.9);
  CHECK(b.positionMm() == a.positionMm());
  CHECK(a.positionMm() > 20.0);
}

TEST_CASE("handHeld is 0 or 1", "[sim]") {
  SimParams params;
  std::string error;
  CHECK(params.applyOverride("handHeld", 1.0));
  CHECK(params.handHeld == 1.0);
  CHECK_FALSE(params.applyOverride("handHeld", 0.5, &error));
  CHECK(error.find("handHeld") != std::string::npos);
  CHECK_FALSE(params.applyOverride("handHeld", 2.0));
}
