// The simulated hand on the surface: the 2D scripts (a line at an angle, a circle, a raster) as
// paths, and the puck and sensor following them in x and y, friction against the motion.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "SimTestSupport.hpp"
#include "sim/HandScript.hpp"
#include "sim/SimDevice.hpp"

using namespace kf;

namespace {
const double kPi = 3.14159265358979323846;
}

TEST_CASE("a line at an angle: its targets lie on the line, at the speed, for length / speed", "[sim][2d]") {
  const HandScript script = HandScript::line(5.0, -2.0, 30.0, 40.0, 80.0);
  REQUIRE(script.isValid());
  const HandTrajectory hand(script);
  for (double t : {0.0, 0.1, 0.25, 0.4999}) {
    const HandTarget target = hand.at(t);
    CHECK(target.positionMm == Approx(5.0 + 80.0 * t * std::cos(kPi / 6)).margin(1e-9));
    CHECK(target.yMm == Approx(-2.0 + 80.0 * t * std::sin(kPi / 6)).margin(1e-9));
    if (t > 0) CHECK(std::hypot(target.speedMmPerS, target.speedYMmPerS) == Approx(80.0));
  }
  const HandTarget end = hand.at(10.0);  // held after 40 / 80 = 0.5 s
  CHECK(end.positionMm == Approx(5.0 + 40.0 * std::cos(kPi / 6)));
  CHECK(end.yMm == Approx(-2.0 + 20.0));
  CHECK(end.speedMmPerS == 0.0);
}

TEST_CASE("a circle: every target on the radius, a turn in 2 pi r / speed, counter-clockwise", "[sim][2d]") {
  const HandScript script = HandScript::circle(10.0, 20.0, 15.0, 60.0, 2.0);
  REQUIRE(script.isValid());
  REQUIRE(script.points2D.size() == 2 * HandScript::kCircleSegments + 1);
  const double turnS = 2 * kPi * 15.0 / 60.0;
  CHECK(script.points2D.back()[0] == Approx(2 * turnS));
  const HandTrajectory hand(script);
  for (int k = 0; k <= 400; ++k) {
    const double t = 2 * turnS * k / 400.0;
    const HandTarget target = hand.at(t);
    const double r = std::hypot(target.positionMm - 10.0, target.yMm - 20.0);
    // Chords of 64 per turn: inside the circle by at most r (1 - cos(pi / 64)) = 0.018 mm.
    CHECK(r <= 15.0 + 1e-9);
    CHECK(r >= 15.0 * std::cos(kPi / HandScript::kCircleSegments) - 1e-9);
  }
  // A quarter turn in: at the top, (cx, cy + r).
  CHECK(hand.at(turnS / 4).positionMm == Approx(10.0).margin(1e-9));
  CHECK(hand.at(turnS / 4).yMm == Approx(35.0));
  // A fractional number of turns stops there.
  const HandScript quarter = HandScript::circle(0, 0, 1, 1, 0.25);
  CHECK(quarter.points2D.back()[1] == Approx(0.0).margin(1e-12));
  CHECK(quarter.points2D.back()[2] == Approx(1.0));
}

TEST_CASE("a raster: rows back and forth, stepping along y, at the speed", "[sim][2d]") {
  const HandScript script = HandScript::raster(-5.0, 0.0, 30.0, 12.0, 4.0, 50.0);
  REQUIRE(script.isValid());
  REQUIRE(script.points2D.size() == 8);
  const double expectX[] = {-5, 25, 25, -5, -5, 25, 25, -5}, expectY[] = {0, 0, 4, 4, 8, 8, 12, 12};
  for (int k = 0; k < 8; ++k) {
    CHECK(script.points2D[k][1] == expectX[k]);
    CHECK(script.points2D[k][2] == expectY[k]);
  }
  CHECK(script.points2D.back()[0] == Approx((4 * 30.0 + 12.0) / 50.0));  // 4 rows and 12 mm down
  const HandTrajectory hand(script);
  CHECK(std::hypot(hand.at(0.3).speedMmPerS, hand.at(0.3).speedYMmPerS) == Approx(50.0));
  CHECK(hand.at(0.65).speedMmPerS == 0.0);  // stepping down between rows 1 and 2: along y only
  CHECK(hand.at(0.65).speedYMmPerS == Approx(50.0));
}

TEST_CASE("2D scripts that make no path are refused", "[sim][2d]") {
  const double nan = std::nan("");
  CHECK_FALSE(HandScript::line(0, 0, 0, 10, 0).isValid());
  CHECK_FALSE(HandScript::line(0, 0, nan, 10, 5).isValid());
  CHECK_FALSE(HandScript::line(0, 0, 0, -1, 5).isValid());
  CHECK_FALSE(HandScript::circle(0, 0, 5, 10, 0).isValid());
  CHECK_FALSE(HandScript::circle(0, 0, 5, 10, 1001).isValid());
  CHECK_FALSE(HandScript::circle(0, 0, -5, 10, 1).isValid());
  CHECK_FALSE(HandScript::raster(0, 0, 10, 10, 2.5, 10).isValid());
  CHECK_FALSE(HandScript::raster(0, 0, 10, 10, 0, 10).isValid());
  CHECK_FALSE(HandScript::raster(0, 0, 10, 10, 3, -1).isValid());
  CHECK_FALSE(HandScript::path2D({}).isValid());
  CHECK_FALSE(HandScript::path2D({{0, 0, 0}, {1, 0, 2e6}}).isValid());  // beyond handPositionMm
  CHECK_FALSE(HandScript::path2D({{1, 0, 0}, {0.5, 1, 1}}).isValid());  // times descend
  CHECK(HandScript::line(0, 0, 0, 0, 5).isValid());                     // a point: held
}

TEST_CASE("the puck follows a circle in x and y and the sensor reports both", "[sim][2d]") {
  const DeviceSpec spec;
  // 40 mm at 40 mm/s (1 rad/s, well below the hand's 14 rad/s): the spring's lag at the minimum
  // force, 7 mm, is along the tangent, so the puck runs on a circle of sqrt(40^2 - 7^2) = 39.4 mm.
  const double speed = 40.0, radius = 40.0;
  SimDevice sim(spec, SimParams{}, HandScript::circle(0.0, 0.0, radius, speed, 2.0));
  const double turnS = 2 * kPi * radius / speed;
  double rMin = 1e9, rMax = 0;
  for (int k = 0; k < 200; ++k) {  // the second turn
    sim.advanceTo(turnS + k * turnS / 200);
    const double r = std::hypot(sim.positionMm(), sim.positionYMm());
    rMin = std::min(rMin, r), rMax = std::max(rMax, r);
    CHECK(std::hypot(sim.speedMmPerS(), sim.speedYMmPerS()) == Approx(speed).epsilon(0.03));
  }
  INFO("radius " << rMin << " .. " << rMax << " mm");
  CHECK(rMin > 0.97 * radius);
  CHECK(rMax < 1.0 * radius);
  // After the script, the puck at rest: the reports' counts added up are its position on each
  // axis, floor-quantised.
  double sumX = 0, sumY = 0;
  for (const MouseReport& r : test::collectReports(sim, 2 * turnS + 2.0, 0.005)) sumX += r.dxCounts, sumY += r.dyCounts;
  REQUIRE(sim.speedMmPerS() == 0.0);
  CHECK(sumX == std::floor(sim.positionMm() / spec.countMm));
  CHECK(sumY == std::floor(sim.positionYMm() / spec.countMm));
  CHECK(std::fabs(sim.positionYMm()) < 8.0);  // back near the start (40, 0), 7 mm lag behind
  CHECK(sim.positionMm() > 30.0);
}

TEST_CASE("friction on the surface is the same in every direction", "[sim][2d]") {
  // The same line, friction-braked, at angles 0..330 degrees: the puck ends at the same distance
  // along it, and on it. Along x (angle 0) it is the 1D model.
  const DeviceSpec spec;
  auto travel = [&](double angleDeg, double& off) {
    SimDevice sim(spec, SimParams{}, HandScript::line(0, 0, angleDeg, 30.0, 100.0));
    for (int ms = 1; ms <= 600; ++ms) {
      sim.commandForce(sim.timeS(), 0.4f);
      sim.advanceTo(ms * 0.001);
    }
    const double a = angleDeg * kPi / 180;
    off = -sim.positionMm() * std::sin(a) + sim.positionYMm() * std::cos(a);
    return sim.positionMm() * std::cos(a) + sim.positionYMm() * std::sin(a);
  };
  double off = 0;
  const double along0 = travel(0, off);
  SimDevice oneD(spec, SimParams{}, HandScript::path({{0.0, 0.0}, {0.3, 30.0}}));
  for (int ms = 1; ms <= 600; ++ms) {
    oneD.commandForce(oneD.timeS(), 0.4f);
    oneD.advanceTo(ms * 0.001);
  }
  CHECK(along0 == oneD.positionMm());  // bit for bit
  CHECK(along0 > 10.0);                // it moved, braked: the spring needs 20 mm of lag at 0.4 N
  for (int deg = 30; deg < 360; deg += 30) {
    const double along = travel(deg, off);
    INFO(deg << " degrees: " << along << " mm along, " << off << " mm off the line");
    // The puck sticks and slips against the spring; a stop decided one 0.1 ms step earlier or
    // later by rounding (sin, cos) moves the end by up to a step's travel at 100 mm/s, 0.01 mm
    // (measured: 3.3e-4 mm along, 7e-6 mm off). Friction per axis instead of against the motion
    // would brake a diagonal line sqrt(2) times harder (millimetres).
    CHECK(std::fabs(along - along0) < 0.01);
    CHECK(std::fabs(off) < 1e-3);
  }
}

TEST_CASE("along x alone the hand pushes as the 1D model did, to the last bit", "[sim][2d]") {
  // The 1D model's spring-damper: the errors in metres first, then the gains, clamped. Any other
  // order of the same arithmetic rounds differently and moves a 1D scene in its last bits.
  const DeviceSpec spec;
  const SimParams params;
  const HandScript script = HandScript::path({{0.0, 0.0}, {0.2, 20.0}, {0.4, 5.0}});
  const HandTrajectory hand(script);
  SimDevice sim(spec, params, script);
  for (int i = 0; i < 3000; ++i) {
    const double t = sim.timeS(), puckMm = sim.positionMm(), puckMmPerS = sim.speedMmPerS();
    sim.commandForce(t, 0.3f);
    sim.advanceTo(t + 1.5 * params.stepS);  // one step: the push is decided at its start
    const HandTarget target = hand.at(t);
    const double errorM = (target.positionMm - puckMm) * 1e-3;
    const double speedErrorMPerS = (target.speedMmPerS - puckMmPerS) * 1e-3;
    const double expected = std::clamp(params.handStiffnessNPerM * errorM + params.handDampingNSPerM * speedErrorMPerS,
                                       -params.handMaxForceN, params.handMaxForceN);
    INFO("step " << i);
    REQUIRE(sim.handForceN() == expected);
  }
}
