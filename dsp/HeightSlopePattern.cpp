#include "HeightSlopePattern.hpp"

namespace kf::patterns {

void BumpPattern::set(double periodMm, double widthMm, bool valleys, double anchorMm) {
  coordinate_.setPeriod(periodMm, anchorMm);
  if (widthMm > 0.0 && std::isfinite(widthMm)) widthMm_ = widthMm;
  omega_ = std::clamp(widthMm_ / coordinate_.periodMm(), 1e-6, 1.0);
  valleys_ = valleys;
  if (omega_ == harmonicsOmega_ && valleys_ == harmonicsValleys_) return;
  const double half = 0.5 * omega_, b = 2.0 * kPi / omega_;
  // E(q) = integral of e^(i q u) over [0, half] = half e^(i q half / 2) sinc(q half / 2).
  auto E = [half](double q) {
    const double x = 0.5 * q * half;
    // A negative amplitude times polar(1, x): std::polar's modulus must not be negative (libc++: NaN).
    return half * (x == 0.0 ? 1.0 : std::sin(x) / x) * std::polar(1.0, x);
  };
  for (int k = 1; k <= kMaxHarmonics; ++k) {
    const double a = 2.0 * kPi * k;
    const std::complex<double> first = (E(b - a) - E(-b - a)) / std::complex<double>(0.0, 2.0);
    const std::complex<double> second = std::polar(1.0, -a * omega_) * std::conj(first);
    climbingUp_[k - 1] = valleys_ ? second : first;
    climbingDown_[k - 1] = valleys_ ? first : second;
  }
  harmonicsOmega_ = omega_;
  harmonicsValleys_ = valleys_;
}

double BumpPattern::height(double f) const {
  const double h = f < omega_ ? 0.5 * (1.0 - std::cos(2.0 * kPi * f / omega_)) : 0.0;
  return valleys_ ? -h : h;
}

double BumpPattern::at(double f, int direction) const {
  if (f >= omega_) return 0.0;
  const double slope = std::sin(2.0 * kPi * f / omega_) * (valleys_ ? -1.0 : 1.0);  // dh/du over pi/omega
  return std::max(0.0, direction * slope);
}

double BumpPattern::climbTo(double f, int direction) const {
  // Along +1 a bump climbs on [0, omega/2) and descends on [omega/2, omega); a valley the other
  // way round. Moving -1 climbs where +1 descends.
  const bool climbsFirstHalf = (direction > 0) != valleys_;
  const double half = 0.5 * omega_;
  const double bump = f < omega_ ? 0.5 * (1.0 - std::cos(2.0 * kPi * f / omega_)) : 0.0;
  if (climbsFirstHalf) return f < half ? bump : 1.0;
  if (f < half) return 0.0;
  return f < omega_ ? 1.0 - bump : 1.0;
}

double BumpPattern::level(const Travel& travel, bool antialias) const {
  const double u1 = coordinate_.cycles(travel.toMm);
  const int direction = travel.direction;
  if (!antialias) return at(fractionOf(u1), direction);
  // The climb per cycle of travel, over the steepest (pi / omega): the mean of at() over the travel.
  const double scale = omega_ / kPi;
  const double u0 = coordinate_.cycles(travel.fromMm);
  const double boxed = periodicMean(
      u0, u1, scale, [&](double f) { return scale * climbTo(f, direction); },
      [&](double f) { return at(f, direction); });
  return bandLimitedSeries(boxed, mean(), direction > 0 ? climbingUp_ : climbingDown_, u0, u1, travel,
                           coordinate_.periodMm());
}

void SlopeOfHeight::setFullSlope(double fullSlope) {
  if (fullSlope > 0.0 && std::isfinite(fullSlope)) fullSlope_ = fullSlope;
}

double SlopeOfHeight::level(const Travel& travel, double heightFrom, double heightTo) {
  const double travelMm = std::fabs(travel.toMm - travel.fromMm);
  const double rise = heightTo - heightFrom;
  if (travelMm < kMinTravelMm || !std::isfinite(rise)) return held_;
  return held_ = clampLevel(rise / travelMm / fullSlope_);
}

}  // namespace kf::patterns
