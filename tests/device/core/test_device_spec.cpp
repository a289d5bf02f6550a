#include <catch2/catch.hpp>

#include "core/spec/DeviceSpec.hpp"
#include "sim/SimParams.hpp"

using namespace kf;

TEST_CASE("paper profile numbers", "[spec]") {
  const DeviceSpec spec;
  CHECK(spec.maxSpeedMmPerS() == Approx(333.375));  // the paper's 334 mm/s
  CHECK(spec.audioDelayS() == Approx(0.001));
  CHECK(spec.countMm * spec.updateRateHz == Approx(2.625));  // speed levels 2.6 mm/s apart
  CHECK(spec.isValid());
}

TEST_CASE("spec overrides by key", "[spec]") {
  DeviceSpec spec;
  CHECK(spec.applyOverride("countMm", 0.01));
  CHECK(spec.countMm == 0.01);
  CHECK(spec.applyOverride("maxCountsPerReport", 2047));
  CHECK(spec.maxCountsPerReport == 2047);
  CHECK_FALSE(spec.applyOverride("maxCountsPerReport", 1.5));
  CHECK(spec.applyOverride("magnetLagS", 0.0));
  CHECK(spec.applyOverride("watchdogS", 0.1));
  CHECK_FALSE(spec.applyOverride("watchdogS", 0.0));
  CHECK_FALSE(spec.applyOverride("updateRateHz", -1.0));
  CHECK_FALSE(spec.applyOverride("countMm", std::numeric_limits<double>::quiet_NaN()));
  CHECK_FALSE(spec.applyOverride("noSuchField", 1.0));
  CHECK(spec.updateRateHz == 125.0);
  for (const char* key :
       {"updateRateHz", "minForceN", "maxForceN", "audioLatencyS", "tactileLatencyS", "maxForceSlewNPerS"})
    CHECK(spec.applyOverride(key, 1.0));
  CHECK(spec.applyOverride("forceFramePeriodS", 0.01));
  CHECK(spec.isValid());
  spec.minForceN = 2.0;
  CHECK_FALSE(spec.isValid());
}

TEST_CASE("sim parameter overrides by key", "[spec]") {
  SimParams params;
  CHECK(params.applyOverride("handStiffnessNPerM", 80.0));
  CHECK(params.handStiffnessNPerM == 80.0);
  CHECK(params.applyOverride("handDampingNSPerM", 3.0));
  CHECK(params.applyOverride("handMaxForceN", 2.0));
  CHECK(params.applyOverride("puckMassKg", 0.2));
  CHECK_FALSE(params.applyOverride("puckMassKg", 0.0));
  CHECK(params.applyOverride("dropProbability", 0.5));
  CHECK_FALSE(params.applyOverride("dropProbability", 1.5));
  CHECK(params.applyOverride("seed", 42));
  CHECK(params.seed == 42);
  CHECK(params.applyOverride("liftStartS", 1.0));
  CHECK(params.applyOverride("liftEndS", 1.5));
  REQUIRE(params.liftIntervalsS.size() == 1);
  CHECK(params.liftIntervalsS[0].second == 1.5);
  CHECK_FALSE(params.applyOverride("unknown", 1.0));
}
