// FrictionMouseIn's reconstruction modes against the simulated device's true trajectory.
#include <catch2/catch.hpp>

#include "ReconstructionScenario.hpp"

using kf::HandScript;
using kf::TrajectoryMode;
using kf::test::reconstructAgainstSim;

namespace {

struct Movement {
  const char* name;
  HandScript hand;
  double seconds;
};

std::vector<Movement> movements() {
  return {
      {"slow, 10 mm/s", HandScript::speeds({{10.0, 3.0}}), 3.0},
      {"fast, 250 mm/s", HandScript::speeds({{250.0, 1.0}}), 1.0},
      {"reversing, +-30 mm at 1 Hz", HandScript::path({{0, 0}, {0.5, 30}, {1.0, 0}, {1.5, 30}, {2.0, 0}, {2.5, 30}}),
       2.5},
  };
}

}  // namespace

TEST_CASE("reconstruction modes against the simulated puck: lag and error") {
  for (const Movement& m : movements()) {
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
    CHECK(predictive.lagS <= linear.lagS / 2);
    CHECK(predictive.rmsErrorMm <= linear.rmsErrorMm);
    // Continuous: no sample-to-sample jump beyond what 334 mm/s moves in a sample, plus a count.
    CHECK(linear.maxStepMm < 334.0 / 48000 + 0.021);
    CHECK(predictive.maxStepMm < 2 * 334.0 / 48000 + 0.021);
  }
}
