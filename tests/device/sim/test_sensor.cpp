#include <catch2/catch.hpp>
#include <cmath>
#include <set>

#include "SimTestSupport.hpp"
#include "sim/SimDevice.hpp"

using namespace kf;

namespace {
double reportSpeedMmPerS(const DeviceSpec& spec, const MouseReport& report) {
  return report.dxCounts * spec.countMm * spec.updateRateHz;
}
}  // namespace

TEST_CASE("steady speeds give speed levels 2.625 mm/s apart", "[sensor]") {
  const DeviceSpec spec;
  const double speedMmPerS = GENERATE(50.0, 100.0, -73.0);
  SimDevice sim(spec, SimParams{}, HandScript::speeds({{speedMmPerS, 5.0}}));
  const auto reports = test::collectReports(sim, 3.0);
  REQUIRE(reports.size() == 375);
  std::set<int> counts;
  double sum = 0;
  for (size_t i = 125; i < reports.size(); ++i) {  // after the hand has settled
    counts.insert(reports[i].dxCounts);
    sum += reportSpeedMmPerS(spec, reports[i]);
    CHECK(reports[i].flags == 0);
    CHECK(reports[i].dyCounts == 0);
  }
  // Every report speed is a whole level; a steady speed sits on the two levels around it.
  const double levelMmPerS = spec.countMm * spec.updateRateHz;
  REQUIRE(levelMmPerS == Approx(2.625));
  CHECK(counts.size() == 2);
  CHECK(*counts.rbegin() - *counts.begin() == 1);
  CHECK(*counts.begin() * levelMmPerS <= speedMmPerS);
  CHECK(*counts.rbegin() * levelMmPerS >= speedMmPerS);
  CHECK(sum / 250 == Approx(speedMmPerS).margin(0.1));
}

TEST_CASE("speeds beyond 334 mm/s clip at 127 counts with kSaturated", "[sensor]") {
  const DeviceSpec spec;
  REQUIRE(spec.maxSpeedMmPerS() == Approx(333.375));
  const double speedMmPerS = GENERATE(400.0, -500.0);
  SimDevice sim(spec, SimParams{}, HandScript::speeds({{speedMmPerS, 3.0}}));
  const auto reports = test::collectReports(sim, 2.0);
  long long total = 0;
  for (size_t i = 125; i < reports.size(); ++i) {
    CHECK(std::abs(reports[i].dxCounts) == 127);
    CHECK(reports[i].dxCounts * speedMmPerS > 0);
    CHECK((reports[i].flags & kSaturated) != 0);
    total += reports[i].dxCounts;
  }
  // The excess is lost: the sum of counts covers only 334 mm/s.
  CHECK(std::fabs(total * spec.countMm) == Approx(125 * 127 * spec.countMm).epsilon(1e-9));
  CHECK(std::fabs(total * spec.countMm) < std::fabs(speedMmPerS) * 1.0 * 0.9);
}

TEST_CASE("report timing jitter is Gaussian with the set deviation and keeps order", "[sensor]") {
  const DeviceSpec spec;
  SimParams params;
  params.reportJitterS = 0.001;
  SimDevice sim(spec, params, HandScript::speeds({{60.0, 10.0}}));
  const auto reports = test::collectReports(sim, 8.0);
  REQUIRE(reports.size() >= 995);
  double sum = 0, sumSquares = 0, maxAbs = 0;
  for (size_t k = 0; k < reports.size(); ++k) {
    const double offsetS = reports[k].deviceTimeS - (k + 1) * spec.updatePeriodS();
    sum += offsetS;
    sumSquares += offsetS * offsetS;
    maxAbs = std::max(maxAbs, std::fabs(offsetS));
    if (k > 0) CHECK(reports[k].deviceTimeS > reports[k - 1].deviceTimeS);
  }
  const double n = static_cast<double>(reports.size());
  CHECK(sum / n == Approx(0.0).margin(1e-4));
  CHECK(std::sqrt(sumSquares / n) == Approx(0.001).epsilon(0.1));
  CHECK(maxAbs <= 0.45 * spec.updatePeriodS() + 1e-12);
}

TEST_CASE("dropped reports pass their counts on with kAfterLoss", "[sensor]") {
  const DeviceSpec spec;
  SimParams lossy;
  lossy.dropProbability = 0.2;
  lossy.seed = 3;
  const HandScript hand = HandScript::speeds({{80.0, 2.0}});
  SimDevice clean(spec, SimParams{}, hand);
  SimDevice dropping(spec, lossy, hand);
  const auto all = test::collectReports(clean, 2.0);
  const auto kept = test::collectReports(dropping, 2.0);
  REQUIRE(all.size() == 250);
  CHECK(kept.size() + dropping.droppedReports() == all.size());
  CHECK(dropping.droppedReports() == Approx(50).margin(20));
  long long allSum = 0, keptSum = 0;
  for (const auto& report : all)
    if (report.deviceTimeS <= kept.back().deviceTimeS) allSum += report.dxCounts;
  for (const auto& report : kept) keptSum += report.dxCounts;
  CHECK(keptSum == allSum);  // nothing lost but the timing
  // A report after a gap carries kAfterLoss and the counts of the reports it stands for.
  size_t cleanIndex = 0;
  int flagged = 0;
  for (const auto& report : kept) {
    int expected = 0;
    size_t covered = 0;
    while (cleanIndex < all.size() && all[cleanIndex].deviceTimeS <= report.deviceTimeS + 1e-12) {
      expected += all[cleanIndex++].dxCounts;
      ++covered;
    }
    CHECK(report.dxCounts == expected);
    CHECK(((report.flags & kAfterLoss) != 0) == (covered > 1));
    flagged += covered > 1;
  }
  CHECK(flagged > 10);
}

TEST_CASE("no counts while lifted, kLifted set, tracking resumes after", "[sensor]") {
  const DeviceSpec spec;
  SimParams params;
  params.liftIntervalsS = {{0.5, 0.7}};
  const HandScript hand = HandScript::speeds({{100.0, 2.0}});
  SimDevice clean(spec, SimParams{}, hand);
  SimDevice lifted(spec, params, hand);
  const auto all = test::collectReports(clean, 1.0);
  const auto seen = test::collectReports(lifted, 1.0);
  REQUIRE(all.size() == seen.size());
  long long lostCounts = 0;
  for (size_t k = 0; k < seen.size(); ++k) {
    const double timeS = seen[k].deviceTimeS;
    const bool inLift = timeS >= 0.5 && timeS < 0.7;
    CHECK(((seen[k].flags & kLifted) != 0) == inLift);
    if (inLift) {
      CHECK(seen[k].dxCounts == 0);
      lostCounts += all[k].dxCounts;
    } else if (timeS >= 0.7 + spec.updatePeriodS()) {
      CHECK(seen[k].dxCounts == all[k].dxCounts);
    }
  }
  // 0.2 s at 100 mm/s is lost (the report just after landing starts from the new position).
  CHECK(lostCounts * spec.countMm == Approx(20.0).margin(1.0));
}

TEST_CASE("device clock drift scales timestamps by 1 + ppm * 1e-6", "[sensor]") {
  const DeviceSpec spec;
  SimParams params;
  params.clockDriftPpm = 100.0;
  SimDevice sim(spec, params, HandScript::none());
  const auto reports = test::collectReports(sim, 10.0);
  REQUIRE(reports.size() == 1250);
  for (size_t k = 0; k < reports.size(); k += 97)
    CHECK(reports[k].deviceTimeS == Approx((k + 1) * spec.updatePeriodS() * 1.0001).epsilon(1e-12));
  CHECK(reports.back().deviceTimeS - 10.0 == Approx(0.001).epsilon(1e-6));
}
