#include "patterns/DetentPattern.hpp"

namespace kf::patterns {

void DetentPattern::set(double spacingMm, double crest, double anchorMm) {
  coordinate_.setPeriod(spacingMm, anchorMm);
  if (std::isfinite(crest)) crest_ = std::clamp(crest, 1e-6, 1.0);
  if (crest_ == harmonicsCrest_) return;
  const double c = crest_;
  for (int k = 1; k <= kMaxHarmonics; ++k) {
    const double a = 2.0 * kPi * k;
    const std::complex<double> e = std::polar(1.0, -a * c);
    harmonics_[k - 1] = std::complex<double>(0.0, 1.0) * e / a + (e - 1.0) / (a * a * c);
  }
  sharp_ = std::max(1.0 / (kPi * c), patterns::sharpHarmonic(1.0 / kPi, 1.0));
  harmonicsCrest_ = crest_;
}

double DetentPattern::at(double f, int direction) const { return alongMotion(direction > 0 ? f : fractionOf(1.0 - f)); }

double DetentPattern::level(const Travel& travel, bool antialias) const {
  // Cycles counted along the motion: u moving +, -u moving -.
  const double sign = travel.direction > 0 ? 1.0 : -1.0;
  const double u1 = sign * coordinate_.cycles(travel.toMm);
  if (!antialias) return alongMotion(fractionOf(u1));
  const double u0 = sign * coordinate_.cycles(travel.fromMm);
  const double boxed = periodicMean(
      u0, u1, 0.5 * crest_, [this](double g) { return integralAlongMotion(g); },
      [this](double g) { return alongMotion(g); });
  return bandLimitedSeries(boxed, mean(), harmonics_, u0, u1, travel, coordinate_.periodMm(), sharp_);
}

}  // namespace kf::patterns
