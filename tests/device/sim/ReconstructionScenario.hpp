// Runs FrictionMouseIn's reconstruction against the simulated device's true trajectory, as
// the UGen does in a Score render (lockstep: device time is audio time): per audio block,
// reports up to the block's end, then the block rendered. Shared by the tests and bench/.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "TrajectoryReconstructor.hpp"
#include "sim/SimDevice.hpp"

namespace kf::test {

// A hand movement to reconstruct, and how long it lasts.
struct Movement {
  const char* name;
  HandScript hand;
  double seconds;
};

// Back and forth over 30 mm at 1 Hz for `seconds` (a multiple of 0.5).
inline HandScript reversing30Mm(double seconds) {
  std::vector<std::pair<double, double>> points;
  for (int i = 0; i * 0.5 <= seconds + 1e-9; ++i) points.push_back({i * 0.5, i % 2 ? 30.0 : 0.0});
  return HandScript::path(points);
}

// Slow, fast and reversing: the movements the reconstruction modes are judged on.
inline std::vector<Movement> reconstructionMovements() {
  return {
      {"slow 10 mm/s", HandScript::speeds({{10.0, 3.0}}), 3.0},
      {"fast 250 mm/s", HandScript::speeds({{250.0, 1.0}}), 1.0},
      {"reversing +-30 mm at 1 Hz", reversing30Mm(2.5), 2.5},
  };
}

// The true position and the rendered one, per audio sample.
struct SimRender {
  std::vector<double> truthMm, renderedMm;
  double intervalS = 0.0;  // the report interval the reconstruction used at the end
};

// The simulated mouse reports at mouseRateHz (0: the spec's); the reconstruction is told the
// spec's rate, as a user who opens a mouse without a profile would, and measures the rest.
inline SimRender renderAgainstSim(const HandScript& hand, double seconds, TrajectoryMode mode,
                                  double sampleRateHz = 48000.0, int blockSize = 64, double mouseRateHz = 0.0) {
  const DeviceSpec spec;
  DeviceSpec mouseSpec = spec;
  if (mouseRateHz > 0) mouseSpec.updateRateHz = mouseRateHz;
  SimParams params;
  params.stepS = std::min(params.stepS, 0.2 / mouseSpec.updateRateHz);  // several steps per report
  SimDevice sim(mouseSpec, params, hand);
  TrajectoryReconstructor trajectory(spec.updateRateHz, mode);
  const double dt = 1.0 / sampleRateHz;
  const int numBlocks = static_cast<int>(seconds * sampleRateHz / blockSize);
  SimRender out;
  std::vector<float> x(blockSize);
  MouseReport reports[512];
  for (int b = 0; b < numBlocks; ++b) {
    const double startS = b * blockSize * dt;
    for (int i = 0; i < blockSize; ++i) {
      sim.advanceTo(startS + i * dt);
      out.truthMm.push_back(sim.positionMm());
    }
    const int n = sim.pollReports(startS + blockSize * dt, reports, 512);
    for (int i = 0; i < n; ++i)
      trajectory.addReport(reports[i].deviceTimeS, reports[i].dxCounts * spec.countMm,
                           reports[i].dyCounts * spec.countMm, reports[i].flags);
    trajectory.render(startS, dt, blockSize, 0.0, x.data(), nullptr, nullptr, nullptr);
    out.renderedMm.insert(out.renderedMm.end(), x.begin(), x.end());
  }
  out.intervalS = trajectory.updateIntervalS();
  return out;
}

struct LagFit {
  double rmsErrorMm = 0.0;       // rendered against true position, at zero shift
  double lagS = 0.0;             // the shift of the truth (-30..30 ms) that minimises the RMS error;
                                 // negative: the rendered trajectory leads the truth
  double rmsErrorAtLagMm = 0.0;  // the RMS error at that shift
};

// The lag of the rendered trajectory behind the truth, to the sample, searched both ways (a
// predictor may lead): steps of 4 samples, then the samples around the best. The first skipS
// are left out.
inline LagFit fitLag(const SimRender& render, double sampleRateHz, double skipS) {
  const long skip = static_cast<long>(skipS * sampleRateHz);
  const std::vector<double>& truth = render.truthMm;
  const std::vector<double>& rendered = render.renderedMm;
  const long size = static_cast<long>(std::min(truth.size(), rendered.size()));
  auto rmsAtShift = [&](long shift) {  // rendered[i] against truth[i - shift]
    double sum = 0.0;
    long count = 0;
    for (long i = std::max(skip, skip + shift); i < std::min(size, size + shift); ++i, ++count)
      sum += std::pow(rendered[i] - truth[i - shift], 2);
    return std::sqrt(sum / std::max<long>(count, 1));
  };
  LagFit fit;
  fit.rmsErrorMm = rmsAtShift(0);
  fit.rmsErrorAtLagMm = fit.rmsErrorMm;
  long best = 0;
  auto consider = [&](long shift) {
    if (const double e = rmsAtShift(shift); e < fit.rmsErrorAtLagMm) fit.rmsErrorAtLagMm = e, best = shift;
  };
  const long maxShift = static_cast<long>(0.03 * sampleRateHz);
  for (long shift = -maxShift; shift <= maxShift; shift += 4) consider(shift);
  const long coarse = best;
  for (long shift = coarse - 3; shift <= coarse + 3; ++shift) consider(shift);
  fit.lagS = best / sampleRateHz;
  return fit;
}

struct ReconstructionResult : LagFit {
  double maxStepMm = 0.0;  // largest jump between consecutive samples
  bool finite = true;
};

// hand: the script; seconds: how long; mode: hold, linear or predictive.
inline ReconstructionResult reconstructAgainstSim(const HandScript& hand, double seconds, TrajectoryMode mode,
                                                  double sampleRateHz = 48000.0, int blockSize = 64) {
  const SimRender render = renderAgainstSim(hand, seconds, mode, sampleRateHz, blockSize);
  ReconstructionResult r;
  static_cast<LagFit&>(r) = fitLag(render, sampleRateHz, 0.1);  // 0.1 s: let the first reports arrive
  const std::vector<double>& rendered = render.renderedMm;
  for (size_t i = 1; i < rendered.size(); ++i) {
    r.finite = r.finite && std::isfinite(rendered[i]);
    r.maxStepMm = std::max(r.maxStepMm, std::fabs(rendered[i] - rendered[i - 1]));
  }
  return r;
}

}  // namespace kf::test
