#include "patterns/RaisedCosineBump.hpp"

namespace kf::patterns {

void RaisedCosineBump::setWidth(double omega) {
  omega = std::clamp(omega, 1e-6, 1.0);
  if (omega == omega_) return;
  omega_ = omega;
  const double b = 2.0 * kPi / omega;
  // E_L(q) = L e^(i q L / 2) sinc(q L / 2).
  auto E = [](double length, double q) {
    const double x = 0.5 * q * length;
    // A negative amplitude times polar(1, x): std::polar's modulus must not be negative (libc++: NaN).
    return length * (x == 0.0 ? 1.0 : std::sin(x) / x) * std::polar(1.0, x);
  };
  const double half = 0.5 * omega;
  // Each bound holds from k = 2 / omega on; a part whose every harmonic is below the level needs none.
  auto sharp = [omega](double allK, double amplitude, double power) {
    const double k = patterns::sharpHarmonic(amplitude, power);
    return patterns::sharpHarmonic(allK, 1.0) > 0.0 ? std::max(2.0 / omega, k) : 0.0;
  };
  sharp_ = std::max(sharp(omega / kPi, 4.0 / (3.0 * kPi * omega), 2.0),
                    sharp(0.5 * omega, 2.0 / (3.0 * kPi * omega * omega), 3.0));
  for (int k = 1; k <= kMaxHarmonics; ++k) {
    const double a = 2.0 * kPi * k;
    const std::complex<double> up = (E(half, b - a) - E(half, -b - a)) / std::complex<double>(0.0, 2.0);
    climbingUp_[k - 1] = up;
    climbingDown_[k - 1] = std::polar(1.0, -a * omega) * std::conj(up);
    height_[k - 1] = 0.5 * E(omega, -a) - 0.25 * (E(omega, b - a) + E(omega, -b - a));
  }
}

double RaisedCosineBump::heightTo(double f) const {
  if (f >= omega_) return 0.5 * omega_;
  return 0.5 * f - omega_ / (4.0 * kPi) * std::sin(2.0 * kPi * f / omega_);
}

double RaisedCosineBump::climb(double f, int direction) const {
  if (f >= omega_) return 0.0;
  return std::max(0.0, direction * std::sin(2.0 * kPi * f / omega_));
}

double RaisedCosineBump::climbTo(double f, int direction) const {
  // Along +1 the bump climbs on [0, omega/2) and descends on [omega/2, omega); moving -1 climbs
  // where +1 descends.
  const double half = 0.5 * omega_;
  const double h = height(f);
  if (direction > 0) return f < half ? h : 1.0;
  if (f < half) return 0.0;
  return f < omega_ ? 1.0 - h : 1.0;
}

}  // namespace kf::patterns
