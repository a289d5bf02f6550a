// PuckModel: the puck as a point mass on the surface along x, with Coulomb kinetic friction
// (the magnet's force) and sticking when the push does not overcome it.
#pragma once

namespace kf {

class PuckModel {
 public:
  explicit PuckModel(double massKg) : massKg_(massKg) {}

  // One step of `stepS` under the horizontal push `pushN` and friction magnitude
  // `frictionN`. Acceleration is held constant over the step (exact for piecewise-constant
  // forces). A moving puck whose speed would change sign within the step stops at the zero
  // crossing instead, so stick/slip does not chatter; a resting puck only starts when
  // |push| > friction.
  void step(double stepS, double pushN, double frictionN);

  double positionM() const { return positionM_; }
  double speedMPerS() const { return speedMPerS_; }
  bool isStuck() const { return speedMPerS_ == 0.0; }

 private:
  double massKg_;
  double positionM_ = 0.0;
  double speedMPerS_ = 0.0;
};

}  // namespace kf
