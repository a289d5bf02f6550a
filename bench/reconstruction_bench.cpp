// FrictionMouseIn's reconstruction modes against the simulated device's true trajectory:
// lag and RMS position error for slow, fast and reversing movement, and CPU per sample of
// each mode's render. Prints one JSON object (bench/run.py reads it).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "ReconstructionScenario.hpp"

namespace {

using kf::TrajectoryMode;

// ns per rendered sample of a mode, with reports arriving as at 250 mm/s.
double renderNsPerSample(TrajectoryMode mode) {
  constexpr int kBlock = 64;
  constexpr double kDt = 1.0 / 48000;
  kf::TrajectoryReconstructor trajectory(125.0, mode);
  std::vector<float> x(kBlock), y(kBlock), vx(kBlock), vy(kBlock);
  double nextReportS = 0.0;
  const int blocks = 200000;
  const auto start = std::chrono::steady_clock::now();
  for (int b = 0; b < blocks; ++b) {
    const double startS = b * kBlock * kDt;
    while (nextReportS < startS + kBlock * kDt) {
      trajectory.addReport(nextReportS, 95 * 0.021, 0.0, 0);
      nextReportS += 0.008;
    }
    trajectory.render(startS, kDt, kBlock, 0.0, x.data(), y.data(), vx.data(), vy.data());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (x[0] < -1e30f) std::puts("");  // keep the result alive
  return seconds * 1e9 / (static_cast<double>(blocks) * kBlock);
}

}  // namespace

int main() {
  const char* modeNames[] = {"hold", "linear", "predictive"};
  std::printf("{\n  \"accuracy\": [\n");
  bool first = true;
  for (const kf::test::Movement& m : kf::test::reconstructionMovements()) {
    for (int mode = 0; mode < 3; ++mode) {
      const auto r = kf::test::reconstructAgainstSim(m.hand, m.seconds, static_cast<TrajectoryMode>(mode));
      std::printf(
          "%s    {\"movement\": \"%s\", \"mode\": \"%s\", \"lagMs\": %.3f, \"rmsErrorMm\": %.5f, "
          "\"rmsErrorAtLagMm\": %.5f, \"maxStepMm\": %.5f}",
          first ? "" : ",\n", m.name, modeNames[mode], r.lagS * 1e3, r.rmsErrorMm, r.rmsErrorAtLagMm, r.maxStepMm);
      first = false;
    }
  }
  std::printf("\n  ],\n  \"cpuNsPerSample\": {");
  // Interleaved rounds, so that machine noise hits every mode alike; the median is reported.
  std::vector<double> ns[3];
  for (int round = 0; round < 5; ++round)
    for (int mode = 0; mode < 3; ++mode) ns[mode].push_back(renderNsPerSample(static_cast<TrajectoryMode>(mode)));
  for (int mode = 0; mode < 3; ++mode) {
    std::sort(ns[mode].begin(), ns[mode].end());
    std::printf("%s\"%s\": %.3f", mode ? ", " : "", modeNames[mode], ns[mode][2]);
  }
  std::printf("}\n}\n");
  return 0;
}
