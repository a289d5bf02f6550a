// FrictionMouseIn's reconstruction against report rate: lag and position error of each
// interpolation mode, lockstep (as a Score render), the device spec at the paper's 125 Hz as a
// user who opens a mouse without a profile has it (the reconstruction measures the rate itself).
// Two sets, printed as one JSON object (bench/kfbench/report_rate.py reads it):
// - "recordings": the synthetic hid-recorder files of tests/data/hid (125 Hz 8-bit, 1 kHz 12-bit,
//   8 kHz 16-bit; made from one known trajectory, see the README there) replayed against that
//   trajectory, over the whole movement and up to the first saturated report;
// - "simulated": the simulated puck's mouse at 125 Hz .. 8 kHz.
//   build/bench/kf_report_rate_bench [tests/data/hid]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ReconstructionScenario.hpp"
#include "SyntheticRecordings.hpp"
#include "recordings/ReplayBackend.hpp"

namespace {

using kf::HandScript;
using kf::TrajectoryMode;
using kf::test::LagFit;
using kf::test::SimRender;

constexpr double kSampleRateHz = 48000.0;
const char* const kModes[] = {"hold", "linear", "predictive"};

// The fit's three numbers as JSON members: lagMs, rmsErrorMm, rmsErrorAtLagMm, or with a
// prefix (cleanLagMs, ...).
std::string fitJson(const std::string& prefix, const LagFit& fit) {
  auto key = [&prefix](std::string name) {
    if (!prefix.empty()) name[0] = static_cast<char>(name[0] - 'a' + 'A');
    return "\"" + prefix + name + "\": ";
  };
  char numbers[3][32];
  std::snprintf(numbers[0], sizeof(numbers[0]), "%.4f", fit.lagS * 1e3);
  std::snprintf(numbers[1], sizeof(numbers[1]), "%.5f", fit.rmsErrorMm);
  std::snprintf(numbers[2], sizeof(numbers[2]), "%.5f", fit.rmsErrorAtLagMm);
  return key("lagMs") + numbers[0] + ", " + key("rmsErrorMm") + numbers[1] + ", " + key("rmsErrorAtLagMm") + numbers[2];
}

SimRender firstSeconds(const SimRender& render, double seconds) {
  SimRender out = render;
  const size_t n = std::min(render.truthMm.size(), static_cast<size_t>(seconds * kSampleRateHz));
  out.truthMm.resize(n);
  out.renderedMm.resize(std::min(n, out.renderedMm.size()));
  return out;
}

// One row per file and mode; false if a file does not load.
bool recordings(const std::string& dataDir, std::string& json) {
  kf::test::SyntheticTrajectory truth;
  std::string error;
  if (!truth.load(dataDir + "/synthetic-trajectory.csv", error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return false;
  }
  constexpr double kMotionStartS = 0.2;  // make_synthetic.py's MOTION_START_S: still before
  for (const kf::test::SyntheticMouse& mouse : kf::test::syntheticMice()) {
    const std::string path = dataDir + "/" + mouse.file;
    kf::DeviceSpec spec;
    spec.countMm = mouse.countMm;
    std::vector<kf::TimedReport> reports;
    if (!kf::loadReplayReports(path, spec, reports, error)) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return false;
    }
    size_t saturated = 0;
    double firstSaturatedS = truth.durationS();
    double endXMm = 0.0;
    for (const kf::TimedReport& r : reports) {
      endXMm += r.report.dxCounts * mouse.countMm;
      if (r.report.flags & kf::kSaturated) {
        if (saturated++ == 0) firstSaturatedS = r.hostTimeS;
      }
    }
    for (int mode = 0; mode < 3; ++mode) {
      const SimRender render =
          kf::test::renderReplayAgainstTruth(path, mouse, truth, static_cast<TrajectoryMode>(mode), kSampleRateHz);
      if (render.renderedMm.empty()) {
        std::fprintf(stderr, "%s: the replay did not open\n", path.c_str());
        return false;
      }
      double maxErrorMm = 0.0;
      for (size_t i = static_cast<size_t>(kMotionStartS * kSampleRateHz); i < render.renderedMm.size(); ++i)
        maxErrorMm = std::max(maxErrorMm, std::fabs(render.renderedMm[i] - render.truthMm[i]));
      const LagFit all = kf::test::fitLag(render, kSampleRateHz, kMotionStartS);
      const LagFit clean = kf::test::fitLag(firstSeconds(render, firstSaturatedS), kSampleRateHz, kMotionStartS);
      char line[512];
      std::snprintf(line, sizeof(line),
                    "  {\"file\": \"%s\", \"rateHz\": %.0f, \"countMm\": %.7f, \"limitCounts\": %d, \"mode\": \"%s\", "
                    "\"intervalMs\": %.4f, \"reports\": %zu, \"saturatedReports\": %zu, \"cleanUntilS\": %.4f, "
                    "\"lostMm\": %.4f, \"maxErrorMm\": %.5f, ",
                    mouse.file, mouse.rateHz, mouse.countMm, mouse.limit, kModes[mode], render.intervalS * 1e3,
                    reports.size(), saturated, firstSaturatedS, truth.xMm(truth.durationS()) - endXMm, maxErrorMm);
      json += line + fitJson("", all) + ", " + fitJson("clean", clean) + "},\n";
    }
  }
  return true;
}

void simulated(std::string& json) {
  const kf::test::Movement movements[] = {
      {"steady 100 mm/s", HandScript::speeds({{100.0, 1.5}}), 1.5},
      {"reversing +-30 mm at 1 Hz", kf::test::reversing30Mm(2.0), 2.0},
  };
  for (const kf::test::Movement& m : movements)
    for (double rate : {125, 250, 500, 1000, 2000, 4000, 8000})
      for (int mode = 0; mode < 3; ++mode) {
        const SimRender render =
            kf::test::renderAgainstSim(m.hand, m.seconds, static_cast<TrajectoryMode>(mode), kSampleRateHz, 64, rate);
        const LagFit fit = kf::test::fitLag(render, kSampleRateHz, 0.2);  // 0.2 s: the rate is measured by then
        char line[256];
        std::snprintf(line, sizeof(line),
                      "  {\"movement\": \"%s\", \"rateHz\": %.0f, \"mode\": \"%s\", \"intervalMs\": %.4f, ", m.name,
                      rate, kModes[mode], render.intervalS * 1e3);
        json += line + fitJson("", fit) + "},\n";
      }
}

void closeList(std::string& json) {
  if (json.size() >= 2 && json.compare(json.size() - 2, 2, ",\n") == 0) json.resize(json.size() - 2);
  json += "\n]";
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dataDir = argc > 1 ? argv[1] : KF_HID_DATA_DIR;
  std::string json = "{\"sampleRateHz\": 48000, \"blockSize\": 64, \"specRateHz\": 125,\n\"recordings\": [\n";
  if (!recordings(dataDir, json)) return 1;
  closeList(json);
  json += ",\n\"simulated\": [\n";
  simulated(json);
  closeList(json);
  std::printf("%s}\n", json.c_str());
  return 0;
}
