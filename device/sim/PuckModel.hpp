// PuckModel: the puck as a point mass on the surface, with Coulomb kinetic friction (the magnet's
// force, against the direction of motion) and sticking when the push does not overcome it. Along
// x alone (no push along y, at rest along y) it is the 1D model, step for step.
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
  // The same on the surface, under the push (pushXN, pushYN): friction of magnitude frictionN
  // opposes the velocity (the push's direction when starting); a moving puck whose speed along its
  // direction of motion would reach zero within the step stops there.
  void step(double stepS, double pushXN, double pushYN, double frictionN);

  double positionM() const { return positionM_; }
  double speedMPerS() const { return speedMPerS_; }
  double positionYM() const { return positionYM_; }
  double speedYMPerS() const { return speedYMPerS_; }
  bool isStuck() const { return speedMPerS_ == 0.0 && speedYMPerS_ == 0.0; }

 private:
  double massKg_;
  double positionM_ = 0.0;
  double speedMPerS_ = 0.0;
  double positionYM_ = 0.0;
  double speedYMPerS_ = 0.0;
};

}  // namespace kf
