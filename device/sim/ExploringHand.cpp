#include "sim/ExploringHand.hpp"

#include <algorithm>
#include <cmath>

#include "core/spec/SettingBounds.hpp"

namespace kf {

bool ExploreSettings::isValid() const {
  const ExploreSettings& s = *this;
  for (double v : {s.fromMm, s.toMm, s.slowMmPerS, s.fastMmPerS, s.tiers, s.tierS, s.maxPushN, s.gainNSPerM, s.adaptS})
    if (!std::isfinite(v)) return false;
  auto within = [](const char* name, double value) { return isWithinBounds(*findSettingBounds(name), value); };
  if (!within("handPositionMm", fromMm) || !within("handPositionMm", toMm) || !(fromMm < toMm)) return false;
  if (!(slowMmPerS > 0.0) || !(slowMmPerS <= fastMmPerS) || !within("handSpeedMmPerS", fastMmPerS)) return false;
  if (!(tiers >= 1.0 && tiers <= 100.0) || tiers != std::floor(tiers)) return false;
  if (!(tierS > 0.0) || !within("handDurationS", tierS)) return false;
  if (!(maxPushN > 0.0) || !within("handForceN", maxPushN)) return false;
  if (!(gainNSPerM > 0.0) || !within("handDampingNSPerM", gainNSPerM)) return false;
  return adaptS > 0.0 && within("handDurationS", adaptS);
}

double ExploringHand::intendedSpeedMmPerS(double timeS) const {
  const ExploreSettings& s = settings_;
  const double tiers = s.tiers;
  if (tiers <= 1.0) return s.slowMmPerS;
  const double tier = std::fmod(std::floor(std::max(0.0, timeS) / s.tierS), tiers);
  return s.slowMmPerS * std::pow(s.fastMmPerS / s.slowMmPerS, tier / (tiers - 1.0));
}

double ExploringHand::push(double timeS, double stepS, double positionMm, double speedMmPerS) {
  const ExploreSettings& s = settings_;
  // Turn at the strip's ends (a puck already past an end heads back at once).
  if (direction_ > 0 && positionMm >= s.toMm) direction_ = -1;
  if (direction_ < 0 && positionMm <= s.fromMm) direction_ = 1;
  // How far the puck falls short of the intended speed along the heading (m/s; < 0: too fast).
  const double shortfallMPerS = (intendedSpeedMmPerS(timeS) - direction_ * speedMmPerS) * 1e-3;
  const double correctionN = s.gainNSPerM * shortfallMPerS;
  // It learns the surface only while it moves the way it heads (a turn's shortfall is the turn's,
  // not the surface's resistance), and where the puck is held it presses harder and harder, by its
  // strongest push per adaptS, until the puck slides: it dwells where friction binds it.
  if (speedMmPerS == 0.0)
    expectedResistanceN_ = std::min(expectedResistanceN_ + s.maxPushN * stepS / s.adaptS, s.maxPushN);
  else if (direction_ * speedMmPerS > 0.0)
    expectedResistanceN_ = std::clamp(expectedResistanceN_ + correctionN * stepS / s.adaptS, 0.0, s.maxPushN);
  return direction_ * std::clamp(expectedResistanceN_ + correctionN, -s.maxPushN, s.maxPushN);
}

}  // namespace kf
