#include "DetentPattern.hpp"

namespace kf::patterns {

void DetentPattern::set(double spacingMm, double crest, double anchorMm) {
  coordinate_.setPeriod(spacingMm, anchorMm);
  if (std::isfinite(crest)) crest_ = std::clamp(crest, 1e-6, 1.0);
}

double DetentPattern::at(double f, int direction) const { return alongMotion(direction > 0 ? f : fractionOf(1.0 - f)); }

double DetentPattern::level(const Travel& travel, bool antialias) const {
  // Cycles counted along the motion: u moving +, -u moving -.
  const double sign = travel.direction > 0 ? 1.0 : -1.0;
  const double u1 = sign * coordinate_.cycles(travel.toMm);
  if (!antialias) return alongMotion(fractionOf(u1));
  const double boxed = periodicMean(
      sign * coordinate_.cycles(travel.fromMm), u1, 0.5 * crest_, [this](double g) { return integralAlongMotion(g); },
      [this](double g) { return alongMotion(g); });
  return clampLevel(bandLimited(boxed, mean(), travel, coordinate_.periodMm()));
}

}  // namespace kf::patterns
