// FrictionMouseIn's reconstruction modes against the simulated device's true trajectory.
#include <catch2/catch.hpp>

#include "ReconstructionScenario.hpp"

using kf::TrajectoryMode;
using kf::test::Movement;
using kf::test::reconstructAgainstSim;
using kf::test::reconstructionMovements;

TEST_CASE("reconstruction modes against the simulated puck: lag and error") {
  for (const Movement& m : reconstructionMovements()) {
    const auto hold = reconstructAgainstSim(m.hand, m.seconds, TrajectoryMode::Hold);
    const auto linear = reconstructAgainstSim(m.hand, m.seconds, TrajectoryMode::Linear);
    const auto predictive = reconstructAgainstSim(m.hand, m.seconds, TrajectoryMode::Predictive);
    INFO(m.name << ": hold " << hold.rmsErrorMm << " mm / " << hold.lagS * 1e3 << " ms, linear " << linear.rmsErrorMm
                << " mm / " << linear.lagS * 1e3 << " ms, predictive " << predictive.rmsErrorMm << " mm / "
                << predictive.lagS * 1e3 << " ms");
    CHECK(hold.finite);
    CHECK(linear.finite);
    CHECK(predictive.finite);
    // The paper's linear mode runs one update interval (8 ms) behind the puck.
    CHECK(linear.lagS == Approx(0.008).margin(0.0015));
    CHECK(std::fabs(predictive.lagS) <= linear.lagS / 2);  // leading counts as much as lagging
    CHECK(predictive.rmsErrorMm <= linear.rmsErrorMm);
    // Continuous: no sample-to-sample jump beyond what 334 mm/s moves in a sample, plus a count.
    CHECK(linear.maxStepMm < 334.0 / 48000 + 0.021);
    CHECK(predictive.maxStepMm < 2 * 334.0 / 48000 + 0.021);
  }
}
