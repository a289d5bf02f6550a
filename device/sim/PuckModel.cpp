#include "sim/PuckModel.hpp"

#include <cmath>

namespace kf {

void PuckModel::step(double stepS, double pushN, double frictionN) {
  double direction = 0.0;
  if (speedMPerS_ > 0.0) {
    direction = 1.0;
  } else if (speedMPerS_ < 0.0) {
    direction = -1.0;
  } else {
    // Static: friction holds the puck up to its full value.
    if (pushN > frictionN) {
      direction = 1.0;
    } else if (pushN < -frictionN) {
      direction = -1.0;
    } else {
      return;
    }
  }
  const double accelerationMPerS2 = (pushN - frictionN * direction) / massKg_;
  const double newSpeedMPerS = speedMPerS_ + accelerationMPerS2 * stepS;
  if (newSpeedMPerS * direction < 0.0) {
    // Friction would reverse the motion: stop where the speed reaches zero.
    const double toZeroS = -speedMPerS_ / accelerationMPerS2;
    positionM_ += speedMPerS_ * toZeroS + 0.5 * accelerationMPerS2 * toZeroS * toZeroS;
    speedMPerS_ = 0.0;
    return;
  }
  positionM_ += speedMPerS_ * stepS + 0.5 * accelerationMPerS2 * stepS * stepS;
  speedMPerS_ = newSpeedMPerS;
}

void PuckModel::step(double stepS, double pushXN, double pushYN, double frictionN) {
  if (pushYN == 0.0 && speedYMPerS_ == 0.0) return step(stepS, pushXN, frictionN);  // along x: the 1D model
  double speed = std::hypot(speedMPerS_, speedYMPerS_);
  double dirX = 0.0, dirY = 0.0;  // the direction friction opposes
  if (speed > 0.0) {
    dirX = speedMPerS_ / speed, dirY = speedYMPerS_ / speed;
  } else {
    const double push = std::hypot(pushXN, pushYN);
    if (push <= frictionN) return;  // static: friction holds the puck up to its full value
    dirX = pushXN / push, dirY = pushYN / push;
  }
  const double ax = (pushXN - frictionN * dirX) / massKg_, ay = (pushYN - frictionN * dirY) / massKg_;
  const double along = ax * dirX + ay * dirY;  // acceleration along the motion
  if (speed > 0.0 && along < 0.0 && speed + along * stepS < 0.0) {
    // Friction would reverse the motion: stop where the speed along it reaches zero.
    const double toZeroS = -speed / along;
    positionM_ += speedMPerS_ * toZeroS + 0.5 * ax * toZeroS * toZeroS;
    positionYM_ += speedYMPerS_ * toZeroS + 0.5 * ay * toZeroS * toZeroS;
    speedMPerS_ = speedYMPerS_ = 0.0;
    return;
  }
  positionM_ += speedMPerS_ * stepS + 0.5 * ax * stepS * stepS;
  positionYM_ += speedYMPerS_ * stepS + 0.5 * ay * stepS * stepS;
  speedMPerS_ += ax * stepS;
  speedYMPerS_ += ay * stepS;
}

}  // namespace kf
