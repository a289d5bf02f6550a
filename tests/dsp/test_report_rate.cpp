// ReportRateEstimator and its use by TrajectoryReconstructor: the update interval measured from
// report times at 125 Hz .. 8 kHz, robust to a still mouse, skipped intervals and jitter.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "ReportRateEstimator.hpp"
#include "TrajectoryReconstructor.hpp"

using namespace kf;

namespace {
// A small deterministic generator (the test must not depend on the library's).
struct Lcg {
  uint64_t state = 12345;
  double uniform() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  }
};

// Report times of a mouse polled every 1/rateHz: it skips ~30% of polls (slow movement), goes
// silent for 0.4 s twice, and each time jitters by +-jitterFraction of T.
std::vector<double> mouseTimes(double rateHz, int reports, double jitterFraction, Lcg& random) {
  const double periodS = 1.0 / rateHz;
  std::vector<double> times;
  double pollS = 1.0;
  for (int i = 0; i < reports; ++i) {
    pollS += periodS * (random.uniform() < 0.3 ? 2 : 1);
    if (i == reports / 3 || i == 2 * reports / 3) pollS += 0.4;
    times.push_back(pollS + jitterFraction * periodS * (2 * random.uniform() - 1));
  }
  return times;
}
}  // namespace

TEST_CASE("report rate: measured at every mouse rate despite skips, silences and jitter", "[rate]") {
  Lcg random;
  for (double rateHz : {125.0, 250.0, 500.0, 1000.0, 2000.0, 4000.0, 8000.0}) {
    ReportRateEstimator estimator;
    for (double t : mouseTimes(rateHz, 400, 0.05, random)) estimator.addReport(t);
    INFO(rateHz << " Hz measured " << estimator.rateHz());
    REQUIRE(estimator.hasEstimate());
    CHECK(estimator.rateHz() == Approx(rateHz).epsilon(0.08));
    CHECK(ReportRateEstimator::snapToUsbRateHz(estimator.rateHz()) == rateHz);
  }
}

TEST_CASE("report rate: no estimate from too few intervals or from silence alone", "[rate]") {
  ReportRateEstimator estimator;
  for (int i = 0; i < ReportRateEstimator::kMinIntervals; ++i) estimator.addReport(i * 0.001);  // 15 intervals
  CHECK_FALSE(estimator.hasEstimate());
  CHECK(estimator.rateHz() == 0.0);
  estimator.addReport(ReportRateEstimator::kMinIntervals * 0.001);
  CHECK(estimator.rateHz() == Approx(1000.0));

  ReportRateEstimator still;  // one report a second: a still mouse nudged now and then
  for (int i = 0; i < 100; ++i) still.addReport(i * 1.0);
  CHECK_FALSE(still.hasEstimate());
  still.addReport(std::numeric_limits<double>::quiet_NaN());
  still.addReport(std::numeric_limits<double>::infinity());
  CHECK_FALSE(still.hasEstimate());
}

TEST_CASE("report rate: an odd rate (a 133 Hz Bluetooth mouse) is not snapped", "[rate]") {
  ReportRateEstimator estimator;
  for (int i = 0; i < 40; ++i) estimator.addReport(i * 0.0075);
  CHECK(estimator.rateHz() == Approx(133.33).epsilon(0.001));
  CHECK(ReportRateEstimator::snapToUsbRateHz(estimator.rateHz()) == Approx(133.33).epsilon(0.001));
}

TEST_CASE("reconstruction: a 1 kHz mouse on a 125 Hz spec is reconstructed at 1 kHz", "[rate]") {
  for (auto mode : {TrajectoryMode::Hold, TrajectoryMode::Linear, TrajectoryMode::Predictive}) {
    TrajectoryReconstructor trajectory(125.0, mode);
    const double dxMm = 0.021 * 3;  // 3 counts a millisecond: 63 mm/s
    const double sampleS = 1.0 / 48000;
    std::vector<float> x(64), vx(64);
    double nextReportS = 0.0005;
    float previous = 0.0f, maxStep = 0.0f;
    int reports = 0;
    for (int block = 0; block < 750; ++block) {  // 1 s
      const double startS = block * 64 * sampleS;
      while (nextReportS < startS + 64 * sampleS && nextReportS < 0.8) {
        trajectory.addReport(nextReportS, dxMm, 0.0);
        nextReportS += 0.001;
        ++reports;
      }
      trajectory.render(startS, sampleS, 64, 0.0, x.data(), nullptr, vx.data(), nullptr);
      for (float v : x) maxStep = std::max(maxStep, std::fabs(v - previous)), previous = v;
      if (block == 400) {  // mid-movement
        CHECK(trajectory.updateIntervalS() == 0.001);
        CHECK(vx[0] == Approx(63.0));
      }
    }
    CHECK(trajectory.reportedXMm() == Approx(reports * dxMm));
    CHECK(x.back() == Approx(reports * dxMm));
    CHECK(maxStep < 3 * dxMm);  // continuous where T changed; at most a report's step (hold)
  }
}

TEST_CASE("reconstruction: the spec's rate stands when the reports keep it, jitter and all", "[rate]") {
  TrajectoryReconstructor trajectory(125.0, TrajectoryMode::Linear);
  Lcg random;
  std::vector<float> x(64);
  for (double t : mouseTimes(125.0, 200, 0.2, random)) {
    trajectory.addReport(t, 0.021, 0.0);
    trajectory.render(t, 1.0 / 48000, 64, 0.0, x.data(), nullptr, nullptr, nullptr);
    CHECK(trajectory.updateIntervalS() == 0.008);
  }
  CHECK(trajectory.measuredRateHz() == Approx(125).epsilon(0.25));
  trajectory.reset();
  CHECK(trajectory.measuredRateHz() == 0.0);
}

TEST_CASE("reconstruction: the rate is measured on the device's clock, not on mapped times", "[rate]") {
  // A clock mapping that corrects itself spreads mapped times closer (here by half); the
  // device's own 8 ms stand.
  TrajectoryReconstructor trajectory(125.0, TrajectoryMode::Linear);
  std::vector<float> x(64);
  for (int i = 0; i < 100; ++i) {
    const double deviceS = 0.008 * i;
    trajectory.addReport(0.004 * i, 0.021, 0.0, 0, deviceS);
    trajectory.render(0.004 * i, 1.0 / 48000, 64, 0.0, x.data(), nullptr, nullptr, nullptr);
  }
  CHECK(trajectory.measuredRateHz() == Approx(125.0));
  CHECK(trajectory.updateIntervalS() == 0.008);
}
