#include "sim/PuckModel.hpp"

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

}  // namespace kf
