// Runs FrictionMouseIn's reconstruction against the simulated device's true trajectory, as
// the UGen does in a Score render (lockstep: device time is audio time): per audio block,
// reports up to the block's end, then the block rendered. Shared by the tests and bench/.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "SimDevice.hpp"
#include "TrajectoryReconstructor.hpp"

namespace kf::test {

struct ReconstructionResult {
  double rmsErrorMm = 0.0;       // rendered against true position, at zero shift
  double lagS = 0.0;             // the shift of the truth that minimises the RMS error
  double rmsErrorAtLagMm = 0.0;  // the RMS error at that shift
  double maxStepMm = 0.0;        // largest jump between consecutive samples
  bool finite = true;
};

// hand: the script; seconds: how long; mode: 0 hold, 1 linear, 2 predictive.
inline ReconstructionResult reconstructAgainstSim(const HandScript& hand, double seconds, TrajectoryMode mode,
                                                  double sampleRateHz = 48000.0, int blockSize = 64) {
  const DeviceSpec spec;
  SimDevice sim(spec, SimParams{}, hand);
  TrajectoryReconstructor trajectory(spec.updateRateHz, mode);
  const double dt = 1.0 / sampleRateHz;
  const int numBlocks = static_cast<int>(seconds * sampleRateHz / blockSize);
  std::vector<double> truth, rendered;
  std::vector<float> x(blockSize);
  MouseReport reports[256];
  for (int b = 0; b < numBlocks; ++b) {
    const double startS = b * blockSize * dt;
    for (int i = 0; i < blockSize; ++i) {
      sim.advanceTo(startS + i * dt);
      truth.push_back(sim.positionMm());
    }
    const int n = sim.pollReports(startS + blockSize * dt, reports, 256);
    for (int i = 0; i < n; ++i)
      trajectory.addReport(reports[i].deviceTimeS, reports[i].dxCounts * spec.countMm,
                           reports[i].dyCounts * spec.countMm, reports[i].flags);
    trajectory.render(startS, dt, blockSize, 0.0, x.data(), nullptr, nullptr, nullptr);
    rendered.insert(rendered.end(), x.begin(), x.end());
  }

  ReconstructionResult r;
  const size_t skip = static_cast<size_t>(0.1 * sampleRateHz);  // let the first reports arrive
  auto rmsAtShift = [&](size_t shift) {
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = skip + shift; i < rendered.size(); ++i, ++count) sum += std::pow(rendered[i] - truth[i - shift], 2);
    return std::sqrt(sum / std::max<size_t>(count, 1));
  };
  r.rmsErrorMm = rmsAtShift(0);
  r.rmsErrorAtLagMm = r.rmsErrorMm;
  const size_t maxShift = static_cast<size_t>(0.03 * sampleRateHz);
  for (size_t shift = 1; shift <= maxShift; shift += 4) {
    const double e = rmsAtShift(shift);
    if (e < r.rmsErrorAtLagMm) r.rmsErrorAtLagMm = e, r.lagS = shift * dt;
  }
  for (size_t i = 1; i < rendered.size(); ++i) {
    r.finite = r.finite && std::isfinite(rendered[i]);
    r.maxStepMm = std::max(r.maxStepMm, std::fabs(rendered[i] - rendered[i - 1]));
  }
  return r;
}

}  // namespace kf::test
