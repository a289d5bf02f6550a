// MagnetModel: the simulated electromagnet; its friction force follows the commanded force
// with a first-order lag (time constant magnetLagS), exact for piecewise-constant commands.
#pragma once

#include <cmath>

namespace kf {

class MagnetModel {
 public:
  MagnetModel(double lagS, double stepS, double offForceN)
      : blend_(lagS > 0.0 ? 1.0 - std::exp(-stepS / lagS) : 1.0), commandedN_(offForceN), forceN_(offForceN) {}

  void command(double forceN) { commandedN_ = forceN; }
  void step() { forceN_ += (commandedN_ - forceN_) * blend_; }

  double forceN() const { return forceN_; }
  double commandedN() const { return commandedN_; }

 private:
  double blend_;
  double commandedN_;
  double forceN_;
};

}  // namespace kf
