// FrictionMouseIn's reconstruction against report rate: lag and RMS position error of each
// interpolation mode for mice reporting at 125 Hz .. 8 kHz, against the simulated puck's true
// trajectory (lockstep, as a Score render). The device spec keeps the paper's 125 Hz, as a user
// who opens a mouse without a profile would: the reconstruction measures the rate itself
// (ReportRateEstimator). Its measured T is printed too. Prints a Markdown table, then JSON.
//   build/bench/kf_report_rate_bench > bench/report_rate.md
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "SimDevice.hpp"
#include "TrajectoryReconstructor.hpp"

namespace {

using kf::HandScript;
using kf::TrajectoryMode;

struct Result {
  double lagS = 0, rmsErrorMm = 0, rmsErrorAtLagMm = 0, intervalS = 0;
};

Result run(double rateHz, const HandScript& hand, double seconds, TrajectoryMode mode) {
  constexpr double kSampleRateHz = 48000.0;
  constexpr int kBlock = 64;
  kf::DeviceSpec simSpec;  // the mouse: reports at rateHz
  simSpec.updateRateHz = rateHz;
  kf::SimParams params;
  params.stepS = std::min(1e-4, 0.2 / rateHz);
  kf::SimDevice sim(simSpec, params, hand);
  kf::TrajectoryReconstructor trajectory(125.0, mode);  // the spec the user did not change
  const double dt = 1.0 / kSampleRateHz;
  const int blocks = static_cast<int>(seconds * kSampleRateHz / kBlock);
  std::vector<double> truth, rendered;
  std::vector<float> x(kBlock);
  kf::MouseReport reports[512];
  for (int b = 0; b < blocks; ++b) {
    const double startS = b * kBlock * dt;
    for (int i = 0; i < kBlock; ++i) {
      sim.advanceTo(startS + i * dt);
      truth.push_back(sim.positionMm());
    }
    const int n = sim.pollReports(startS + kBlock * dt, reports, 512);
    for (int i = 0; i < n; ++i)
      trajectory.addReport(reports[i].deviceTimeS, reports[i].dxCounts * simSpec.countMm,
                           reports[i].dyCounts * simSpec.countMm, reports[i].flags);
    trajectory.render(startS, dt, kBlock, 0.0, x.data(), nullptr, nullptr, nullptr);
    rendered.insert(rendered.end(), x.begin(), x.end());
  }
  const size_t skip = static_cast<size_t>(0.2 * kSampleRateHz);  // the rate is measured by then
  auto rmsAt = [&](size_t shift) {
    double sum = 0;
    size_t count = 0;
    for (size_t i = skip + shift; i < rendered.size(); ++i, ++count) sum += std::pow(rendered[i] - truth[i - shift], 2);
    return std::sqrt(sum / std::max<size_t>(count, 1));
  };
  Result r;
  r.intervalS = trajectory.updateIntervalS();
  r.rmsErrorMm = rmsAt(0);
  size_t best = 0;
  double bestRms = r.rmsErrorMm;
  for (size_t shift = 4; shift <= static_cast<size_t>(0.03 * kSampleRateHz); shift += 4)
    if (const double e = rmsAt(shift); e < bestRms) bestRms = e, best = shift;
  for (size_t shift = best > 3 ? best - 3 : 0; shift <= best + 3; ++shift)  // to the sample
    if (const double e = rmsAt(shift); e < bestRms) bestRms = e, best = shift;
  r.lagS = best * dt;
  r.rmsErrorAtLagMm = bestRms;
  return r;
}

}  // namespace

int main() {
  struct Movement {
    const char* name;
    HandScript hand;
    double seconds;
  };
  const Movement movements[] = {
      {"steady 100 mm/s", HandScript::speeds({{100.0, 1.5}}), 1.5},
      {"reversing +-30 mm at 1 Hz", HandScript::path({{0, 0}, {0.5, 30}, {1.0, 0}, {1.5, 30}, {2.0, 0}}), 2.0},
  };
  const char* modes[] = {"hold", "linear", "predictive"};
  const double rates[] = {125, 250, 500, 1000, 2000, 4000, 8000};
  std::string json = "{\"reportRate\": [\n";
  for (const Movement& m : movements) {
    std::printf("\n### %s (48 kHz, 64-sample blocks; spec 125 Hz, rate measured)\n\n", m.name);
    std::printf("| report rate | T used (ms) | mode | lag (ms) | RMS error (mm) | RMS error at lag (mm) |\n");
    std::printf("| ---: | ---: | --- | ---: | ---: | ---: |\n");
    for (double rate : rates)
      for (int mode = 0; mode < 3; ++mode) {
        const Result r = run(rate, m.hand, m.seconds, static_cast<TrajectoryMode>(mode));
        std::printf("| %.0f Hz | %.3f | %s | %.3f | %.4f | %.4f |\n", rate, r.intervalS * 1e3, modes[mode],
                    r.lagS * 1e3, r.rmsErrorMm, r.rmsErrorAtLagMm);
        char line[256];
        std::snprintf(line, sizeof(line),
                      "  {\"movement\": \"%s\", \"rateHz\": %.0f, \"mode\": \"%s\", \"intervalMs\": %.4f, \"lagMs\": "
                      "%.4f, \"rmsErrorMm\": %.5f, \"rmsErrorAtLagMm\": %.5f},\n",
                      m.name, rate, modes[mode], r.intervalS * 1e3, r.lagS * 1e3, r.rmsErrorMm, r.rmsErrorAtLagMm);
        json += line;
      }
  }
  json.resize(json.size() - 2);
  std::printf("\n```json\n%s\n]}\n```\n", json.c_str());
  return 0;
}
