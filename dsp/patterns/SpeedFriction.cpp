#include "patterns/SpeedFriction.hpp"

namespace kf::patterns {

void ViscousFriction::set(double fullSpeedMmPerS) {
  if (fullSpeedMmPerS > 0.0 && std::isfinite(fullSpeedMmPerS)) fullSpeedMmPerS_ = fullSpeedMmPerS;
}

void StickSlipFriction::set(double slipSpeedMmPerS, double stickSpeedMmPerS) {
  if (slipSpeedMmPerS >= 0.0 && std::isfinite(slipSpeedMmPerS)) slipSpeedMmPerS_ = slipSpeedMmPerS;
  if (stickSpeedMmPerS >= 0.0 && std::isfinite(stickSpeedMmPerS)) stickSpeedMmPerS_ = stickSpeedMmPerS;
}

double StickSlipFriction::level(const Travel& travel) {
  const double stick = std::min(stickSpeedMmPerS_, slipSpeedMmPerS_);
  if (!sliding_ && travel.speedMmPerS > slipSpeedMmPerS_)
    sliding_ = true;
  else if (sliding_ && travel.speedMmPerS < stick)
    sliding_ = false;
  return sliding_ ? 0.0 : 1.0;
}

}  // namespace kf::patterns
