// The synthetic hid-recorder recordings of tests/data/hid (written by make_synthetic.py there,
// whose README says how) and the trajectory they were made from; replayed through
// FrictionMouseIn's reconstruction as a Score render does (lockstep). Shared by the tests and
// bench/report_rate_bench.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "../sim/ReconstructionScenario.hpp"
#include "DeviceFactory.hpp"
#include "TrajectoryReconstructor.hpp"

namespace kf::test {

// One mouse of make_synthetic.py's MICE, as it wrote it.
struct SyntheticMouse {
  const char* file;
  double rateHz;
  double countMm;      // 25.4 mm / CPI
  int32_t limit;       // the delta field's logical maximum
  size_t otherEvents;  // reports of the file that are not mouse reports (a replay skips them)
};

inline const std::vector<SyntheticMouse>& syntheticMice() {
  static const std::vector<SyntheticMouse> mice = {
      {"synthetic-125hz-8bit-boot.hid", 125.0, 0.021, 127, 0},
      {"synthetic-1khz-12bit-gaming.hid", 1000.0, 25.4 / 1600, 2047, 1},
      {"synthetic-8khz-16bit-gaming.hid", 8000.0, 25.4 / 3200, 32767, 1},
  };
  return mice;
}

// synthetic-trajectory.csv: t_s,x_mm,y_mm,buttons on a regular grid; positions between its
// samples interpolated linearly (at most 0.5 um off the curve: |x''| < 16000 mm/s^2 over 0.5 ms
// steps gives |x''| h^2 / 8 = 0.5 um).
class SyntheticTrajectory {
 public:
  bool load(const std::string& path, std::string& error) {
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      Sample s;
      unsigned buttons = 0;
      if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%u", &s.t, &s.x, &s.y, &buttons) != 4) {
        error = path + ": bad line '" + line + "'";
        return false;
      }
      s.buttons = buttons;
      samples_.push_back(s);
    }
    if (samples_.size() < 2) {
      error = path + ": no trajectory";
      return false;
    }
    stepS_ = samples_[1].t - samples_[0].t;
    return true;
  }
  double durationS() const { return samples_.back().t; }
  double xMm(double t) const { return at(t, &Sample::x); }
  double yMm(double t) const { return at(t, &Sample::y); }
  // Buttons change on grid points only: the state at the sample at or before t.
  uint32_t buttons(double t) const { return samples_[index(t + 1e-9)].buttons; }

 private:
  struct Sample {
    double t = 0, x = 0, y = 0;
    uint32_t buttons = 0;
  };
  size_t index(double t) const {
    const double i = std::floor(t / stepS_);
    return i < 0 ? 0 : std::min(static_cast<size_t>(i), samples_.size() - 2);
  }
  double at(double t, double Sample::*value) const {
    const size_t i = index(t);
    const double f = std::clamp((t - samples_[i].t) / stepS_, 0.0, 1.0);
    return samples_[i].*value + f * (samples_[i + 1].*value - samples_[i].*value);
  }
  std::vector<Sample> samples_;
  double stepS_ = 0.0;
};

// X rendered by the reconstruction in `mode` from the lockstep replay of `path` (the spec at
// its default 125 Hz, the rate measured, as a user without a profile has it), against the
// trajectory's X, per audio sample.
inline SimRender renderReplayAgainstTruth(const std::string& path, const SyntheticMouse& mouse,
                                          const SyntheticTrajectory& truth, TrajectoryMode mode,
                                          double sampleRateHz = 48000.0, int blockSize = 64) {
  DeviceSpec spec;
  spec.countMm = mouse.countMm;
  std::string error;
  const std::unique_ptr<Device> device = openReplayDevice(path, spec, true, error);
  SimRender out;
  if (!device) return out;
  TrajectoryReconstructor trajectory(spec.updateRateHz, mode);
  const double dt = 1.0 / sampleRateHz;
  const int numBlocks = static_cast<int>(truth.durationS() * sampleRateHz / blockSize);
  std::vector<float> x(blockSize);
  MouseReport reports[512];
  for (int b = 0; b < numBlocks; ++b) {
    const double startS = b * blockSize * dt;
    for (int i = 0; i < blockSize; ++i) out.truthMm.push_back(truth.xMm(startS + i * dt));
    device->pump(startS + blockSize * dt);
    int n = 0;
    while ((n = device->popReports(reports, 512)) > 0)
      for (int i = 0; i < n; ++i)
        trajectory.addReport(reports[i].deviceTimeS, reports[i].dxCounts * spec.countMm,
                             reports[i].dyCounts * spec.countMm, reports[i].flags);
    trajectory.render(startS, dt, blockSize, 0.0, x.data(), nullptr, nullptr, nullptr);
    out.renderedMm.insert(out.renderedMm.end(), x.begin(), x.end());
  }
  out.intervalS = trajectory.updateIntervalS();
  return out;
}

}  // namespace kf::test
