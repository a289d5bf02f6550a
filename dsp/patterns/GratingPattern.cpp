#include "patterns/GratingPattern.hpp"

namespace kf::patterns {

void GratingPattern::set(double periodMm, double duty, double edgeMm, double anchorMm) {
  coordinate_.setPeriod(periodMm, anchorMm);
  if (std::isfinite(duty)) duty_ = std::clamp(duty, 0.0, 1.0);
  if (std::isfinite(edgeMm)) edgeMm_ = edgeMm;
  edge_ = std::clamp(edgeMm_ / coordinate_.periodMm(), 0.0, std::min(duty_, 1.0 - duty_));
  if (duty_ == harmonicsDuty_ && edge_ == harmonicsEdge_) return;
  for (int k = 1; k <= kMaxHarmonics; ++k) {
    const double e = kPi * k * edge_, sincEdge = e > 0.0 ? std::sin(e) / e : 1.0;
    // amplitude * polar(1, phase): the amplitude may be negative, which std::polar does not allow
    // (libc++ returns NaN for it).
    harmonics_[k - 1] = std::sin(kPi * k * duty_) / (kPi * k) * sincEdge * std::polar(1.0, -kPi * k * (duty_ + edge_));
  }
  const bool flat = duty_ == 0.0 || duty_ == 1.0;
  const double hard = patterns::sharpHarmonic(1.0 / kPi, 1.0);
  sharp_ = flat ? 0.0 : (edge_ > 0.0 ? std::min(hard, patterns::sharpHarmonic(1.0 / (kPi * kPi * edge_), 2.0)) : hard);
  harmonicsDuty_ = duty_;
  harmonicsEdge_ = edge_;
}

double GratingPattern::at(double f) const {
  const double d = duty_, e = edge_;
  if (f < e) return f / e;
  if (f < d) return 1.0;
  if (f < d + e) return 1.0 - (f - d) / e;
  return 0.0;
}

double GratingPattern::integralTo(double f) const {
  const double d = duty_, e = edge_;
  if (f < e) return f * f / (2.0 * e);
  if (f < d) return f - 0.5 * e;
  if (f < d + e) {
    const double g = f - d;
    return d - 0.5 * e + g - g * g / (2.0 * e);
  }
  return d;
}

double GratingPattern::level(const Travel& travel, bool antialias) const {
  const double u1 = coordinate_.cycles(travel.toMm);
  if (!antialias) return at(fractionOf(u1));
  const double u0 = coordinate_.cycles(travel.fromMm);
  const double boxed = periodicMean(
      u0, u1, duty_, [this](double f) { return integralTo(f); }, [this](double f) { return at(f); });
  return bandLimitedSeries(boxed, duty_, harmonics_, u0, u1, travel, coordinate_.periodMm(), sharp_);
}

}  // namespace kf::patterns
