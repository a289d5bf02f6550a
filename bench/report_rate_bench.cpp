// FrictionMouseIn's reconstruction against report rate: lag and RMS position error of each
// interpolation mode for mice reporting at 125 Hz .. 8 kHz, against the simulated puck's true
// trajectory (lockstep, as a Score render). The device spec keeps the paper's 125 Hz, as a user
// who opens a mouse without a profile would: the reconstruction measures the rate itself
// (ReportRateEstimator). Its measured T is printed too. Prints a Markdown table, then JSON.
//   build/bench/kf_report_rate_bench > bench/report_rate.md
#include <cstdio>
#include <string>
#include <vector>

#include "ReconstructionScenario.hpp"

namespace {

using kf::HandScript;
using kf::TrajectoryMode;

struct Result {
  double lagS = 0, rmsErrorMm = 0, rmsErrorAtLagMm = 0, intervalS = 0;
};

Result run(double rateHz, const HandScript& hand, double seconds, TrajectoryMode mode) {
  constexpr double kSampleRateHz = 48000.0;
  const kf::test::SimRender render = kf::test::renderAgainstSim(hand, seconds, mode, kSampleRateHz, 64, rateHz);
  const kf::test::LagFit fit = kf::test::fitLag(render, kSampleRateHz, 0.2);  // 0.2 s: the rate is measured by then
  return {fit.lagS, fit.rmsErrorMm, fit.rmsErrorAtLagMm, render.intervalS};
}

}  // namespace

int main() {
  const kf::test::Movement movements[] = {
      {"steady 100 mm/s", HandScript::speeds({{100.0, 1.5}}), 1.5},
      {"reversing +-30 mm at 1 Hz", kf::test::reversing30Mm(2.0), 2.0},
  };
  const char* modes[] = {"hold", "linear", "predictive"};
  const double rates[] = {125, 250, 500, 1000, 2000, 4000, 8000};
  std::string json = "{\"reportRate\": [\n";
  for (const kf::test::Movement& m : movements) {
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
