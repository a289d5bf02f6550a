// MagnetModel: the simulated electromagnet; its friction force follows the commanded force
// with a first-order lag (time constant magnetLagS), exact for piecewise-constant commands,
// also for commands that change within a step (8 kHz frames on the simulation's 100 us steps).
#pragma once

#include <algorithm>
#include <cmath>

namespace kf {

class MagnetModel {
 public:
  MagnetModel(double lagS, double stepS, double offForceN)
      : lagS_(lagS),
        stepS_(stepS),
        blend_(lagS > 0.0 ? 1.0 - std::exp(-stepS / lagS) : 1.0),
        commandedN_(offForceN),
        forceN_(offForceN),
        withinStepN_(offForceN) {}

  // A new command `intoStepS` after the start of the step in progress (0 .. stepS): up to then
  // the force follows the command before it.
  void command(double forceN, double intoStepS = 0.0) {
    intoStepS = std::clamp(intoStepS, sinceStepS_, stepS_);
    if (intoStepS > sinceStepS_) follow(intoStepS - sinceStepS_);
    sinceStepS_ = intoStepS;
    commandedN_ = forceN;
  }
  void step() {
    if (sinceStepS_ == 0.0)
      withinStepN_ += (commandedN_ - withinStepN_) * blend_;
    else
      follow(stepS_ - sinceStepS_);
    sinceStepS_ = 0.0;
    forceN_ = withinStepN_;
  }

  double forceN() const { return forceN_; }  // at the start of the step in progress
  double commandedN() const { return commandedN_; }

 private:
  void follow(double durationS) {
    withinStepN_ += (commandedN_ - withinStepN_) * (lagS_ > 0.0 ? 1.0 - std::exp(-durationS / lagS_) : 1.0);
  }

  double lagS_;
  double stepS_;
  double blend_;  // over a whole step
  double commandedN_;
  double forceN_;
  double withinStepN_;  // the force at sinceStepS_ into the step in progress
  double sinceStepS_ = 0.0;
};

}  // namespace kf
