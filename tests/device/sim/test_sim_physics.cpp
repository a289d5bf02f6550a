#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include "SimTestSupport.hpp"
#include "sim/SimDevice.hpp"

using namespace kf;

TEST_CASE("constant push above friction accelerates at (F - f) / m", "[sim]") {
  const DeviceSpec spec;
  const SimParams params;  // 0.1 kg
  const double pushN = GENERATE(0.5, -0.3, 1.0);
  SimDevice sim(spec, params, HandScript::constantForce(pushN));
  const double direction = pushN > 0 ? 1.0 : -1.0;
  const double accelerationMPerS2 = (pushN - direction * spec.minForceN) / params.puckMassKg;
  for (double timeS : {0.1, 0.25, 0.5}) {
    sim.advanceTo(timeS);
    CHECK(sim.positionMm() == Approx(0.5 * accelerationMPerS2 * timeS * timeS * 1000.0).epsilon(1e-6));
    CHECK(sim.speedMmPerS() == Approx(accelerationMPerS2 * timeS * 1000.0).epsilon(1e-6));
  }
}

TEST_CASE("a push below friction does not move the puck at all", "[sim]") {
  const DeviceSpec spec;
  for (double pushN : {0.1, -0.13, 0.14}) {
    SimDevice sim(spec, SimParams{}, HandScript::constantForce(pushN));
    const auto reports = test::collectReports(sim, 1.0);
    CHECK(sim.positionMm() == 0.0);
    CHECK(sim.speedMmPerS() == 0.0);
    REQUIRE(reports.size() == 125);
    for (const MouseReport& report : reports) CHECK(report.dxCounts == 0);
  }
  // With the magnet on, a push that moves it with the magnet off is held: once the magnet's
  // force has risen past the push, the puck stops and stays.
  SimDevice sim(spec, SimParams{}, HandScript::constantForce(0.5));
  sim.commandForce(0.0, 0.6f);
  sim.advanceTo(0.05);
  const double heldMm = sim.positionMm();
  CHECK(heldMm < 0.1);
  CHECK(sim.speedMmPerS() == 0.0);
  sim.advanceTo(0.5);
  CHECK(sim.positionMm() == heldMm);
}

TEST_CASE("magnet force reaches 63.2 % of a step after magnetLagS", "[sim]") {
  DeviceSpec spec;
  SimDevice sim(spec, SimParams{}, HandScript::none());
  sim.advanceTo(0.1);
  CHECK(sim.frictionN() == Approx(spec.minForceN));
  sim.commandForce(0.1, 1.4f);
  sim.advanceTo(0.1 + spec.magnetLagS);
  const double expectedN = spec.minForceN + (1.0 - std::exp(-1.0)) * (1.4f - spec.minForceN);
  CHECK(sim.frictionN() == Approx(expectedN).epsilon(1e-6));
  sim.advanceTo(0.1 + 10 * spec.magnetLagS);
  CHECK(sim.frictionN() == Approx(1.4).epsilon(1e-4));
  sim.driveOff();
  sim.advanceTo(0.2 + 10 * spec.magnetLagS);
  CHECK(sim.frictionN() == Approx(spec.minForceN).epsilon(1e-4));
}

TEST_CASE("the magnet follows commands at 8 kHz exactly, between the simulation's 100 us steps", "[sim]") {
  // Frames 125 us apart alternate 0.3 and 1.2 N; the magnet's force at each step's end is the
  // first-order lag's exact solution over the commands at their own times (a fast coil: 50 us),
  // not over commands moved to the steps' starts (as before: 0.397 N off).
  DeviceSpec spec;
  spec.magnetLagS = 50e-6;
  const SimParams params;
  REQUIRE(params.stepS == Approx(100e-6));
  SimDevice sim(spec, params, HandScript::none());
  double exactN = spec.minForceN, commandedN = spec.minForceN, exactS = 0.0;
  auto follow = [&](double untilS) {
    exactN += (commandedN - exactN) * (1.0 - std::exp(-(untilS - exactS) / spec.magnetLagS));
    exactS = untilS;
  };
  double worst = 0.0;
  int stepsChecked = 0;
  for (int k = 0; k < 160; ++k) {  // 20 ms
    const double frameS = 0.01 + k * 125e-6;
    // Every step that ends before this frame: the magnet against the exact solution.
    while (sim.timeS() + params.stepS <= frameS + 1e-12) {
      const double endS = sim.timeS() + params.stepS;
      sim.advanceTo(endS);
      if (endS > 0.01) {
        follow(endS);
        worst = std::max(worst, std::fabs(sim.frictionN() - exactN));
        ++stepsChecked;
      }
    }
    follow(frameS);
    commandedN = k % 2 ? 1.2f : 0.3f;  // as the device sends it, a float
    sim.commandForce(frameS, static_cast<float>(commandedN));
  }
  INFO("steps checked " << stepsChecked);
  CHECK(stepsChecked >= 190);
  CHECK(worst < 1e-9);
}

TEST_CASE("the hand follows a steady 100 mm/s target with the magnet off", "[sim]") {
  const DeviceSpec spec;
  const SimParams params;
  SimDevice sim(spec, params, HandScript::speeds({{100.0, 3.0}}));
  sim.advanceTo(2.0);
  CHECK(sim.speedMmPerS() == Approx(100.0).margin(0.1));
  // Steady state: the spring carries the friction, lag = f / k.
  const double lagMm = spec.minForceN / params.handStiffnessNPerM * 1000.0;
  CHECK(200.0 - sim.positionMm() == Approx(lagMm).margin(0.05));
  // The sensor sees the same speed.
  const auto reports = test::collectReports(sim, 2.5);
  double countsSum = 0;
  int counted = 0;
  for (const MouseReport& report : reports) {
    if (report.deviceTimeS <= 2.0) continue;
    countsSum += report.dxCounts;
    ++counted;
  }
  CHECK(countsSum * spec.countMm / (counted * spec.updatePeriodS()) == Approx(100.0).margin(0.1));
}

// Crossing time of [startMm, startMm + widthMm) with `fragmentForceN` commanded while the puck
// is inside (as FrictionOut would), hand target at 100 mm/s.
static double crossingTimeS(double startMm, double widthMm, float fragmentForceN) {
  const DeviceSpec spec;
  SimDevice sim(spec, SimParams{}, HandScript::speeds({{100.0, 10.0}}));
  double enteredS = -1.0;
  for (int ms = 1; ms < 10000; ++ms) {
    const double timeS = ms * 0.001;
    const double xMm = sim.positionMm();
    const bool inside = xMm >= startMm && xMm < startMm + widthMm;
    if (inside && enteredS < 0) enteredS = sim.timeS();
    if (xMm >= startMm + widthMm) return sim.timeS() - enteredS;
    sim.commandForce(sim.timeS(), inside ? fragmentForceN : static_cast<float>(spec.minForceN));
    sim.advanceTo(timeS);
  }
  return -1.0;
}

TEST_CASE("friction of 0.45 N slows the crossing of the pilot fragments", "[sim]") {
  for (double widthMm : {6.0, 48.0}) {
    const double freeS = crossingTimeS(60.0, widthMm, 0.14f);
    const double brakedS = crossingTimeS(60.0, widthMm, 0.45f);
    INFO("width " << widthMm << " mm: " << freeS << " s at 0.14 N, " << brakedS << " s at 0.45 N");
    CHECK(freeS == Approx(widthMm / 100.0).epsilon(0.05));
    CHECK(brakedS > 1.2 * freeS);
  }
}

TEST_CASE("stick/slip settles without chattering", "[sim]") {
  const DeviceSpec spec;
  // Move 20 mm, then hold: the puck must come to rest and stay exactly there.
  SimDevice sim(spec, SimParams{}, HandScript::path({{0.0, 0.0}, {0.2, 20.0}}));
  sim.advanceTo(1.0);
  const double restMm = sim.positionMm();
  CHECK(sim.speedMmPerS() == 0.0);
  CHECK(std::fabs(20.0 - restMm) <= spec.minForceN / SimParams{}.handStiffnessNPerM * 1000.0 + 1e-9);
  int signChanges = 0;
  double lastSpeed = 0.0;
  for (int i = 1; i <= 1000; ++i) {
    sim.advanceTo(1.0 + i * 1e-3);
    if (sim.speedMmPerS() * lastSpeed < 0) ++signChanges;
    lastSpeed = sim.speedMmPerS();
  }
  CHECK(signChanges == 0);
  CHECK(sim.positionMm() == restMm);
}

TEST_CASE("the simulator is deterministic bit for bit", "[sim]") {
  DeviceSpec spec;
  SimParams params;
  params.reportJitterS = 0.0005;
  params.dropProbability = 0.1;
  params.clockDriftPpm = 50;
  params.seed = 7;
  auto run = [&] {
    SimDevice sim(spec, params, HandScript::speeds({{150.0, 0.5}, {-80.0, 0.5}, {0.0, 0.2}}));
    std::vector<MouseReport> reports;
    MouseReport buffer[8];
    for (int ms = 1; ms <= 1200; ++ms) {
      if (ms % 3 == 0) sim.commandForce(ms * 0.001, 0.14f + 0.001f * static_cast<float>(ms % 500));
      const int n = sim.pollReports(ms * 0.001, buffer, 8);
      reports.insert(reports.end(), buffer, buffer + n);
    }
    return std::make_pair(reports, sim.positionMm());
  };
  const auto first = run();
  const auto second = run();
  REQUIRE(first.first.size() == second.first.size());
  REQUIRE(!first.first.empty());
  CHECK(std::memcmp(first.first.data(), second.first.data(), first.first.size() * sizeof(MouseReport)) == 0);
  CHECK(std::memcmp(&first.second, &second.second, sizeof(double)) == 0);
}
