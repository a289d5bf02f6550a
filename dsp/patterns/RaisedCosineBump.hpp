// One raised-cosine bump of width omega (cycles, 0 < omega <= 1) from 0 in every period, and the
// climb met crossing it: the one-axis parts that BumpPattern (1D) and GridBumpsPattern (2D, per
// axis) band-limit, each with its integral from 0 and its Fourier coefficients in closed form.
//   height:  b(f) = (1 - cos(2 pi f / omega)) / 2 on [0, omega), 0 on [omega, 1)
//   climb:   c(f, s) = max(0, s sin(2 pi f / omega)) on [0, omega), 0 beyond: b's slope in the
//            direction s = +-1 over the steepest (pi / omega per cycle), where it climbs.
// Harmonics (g(f) = mean + sum_k 2 Re(C_k e^(i 2 pi k f)), C_k the integral of g e^(-i 2 pi k f)
// over a period), a = 2 pi k, b = 2 pi / omega, E_L(q) = integral of e^(i q f) over [0, L):
//   climbing along +1 (sin(b f) on [0, omega / 2)): C+_k = (E_half(b - a) - E_half(-b - a)) / 2i;
//   along -1 the mirror image about omega / 2: C-_k = e^(-i a omega) conj(C+_k);
//   height: C_k = E_omega(-a) / 2 - (E_omega(b - a) + E_omega(-b - a)) / 4.
// Their bounds (sharpHarmonic): the climb is a half-sine pulse of omega / 2 cycles,
// |C+_k| = (omega / pi) |cos(pi k omega / 2)| / |1 - (k omega)^2|, <= omega / pi (its integral) and,
// for k omega >= 2 (1 / ((k omega)^2 - 1) <= 4 / (3 (k omega)^2)), <= 4 / (3 pi omega k^2); the
// height's |C_k| = (omega / 2) |sinc(pi k omega)| / |1 - (k omega)^2| <= omega / 2, and for
// k omega >= 2 <= 2 / (3 pi omega^2 k^3).
#pragma once

#include "patterns/PatternTravel.hpp"

namespace kf::patterns {

class RaisedCosineBump {
 public:
  RaisedCosineBump() { setWidth(0.5); }
  // omega is clamped to [1e-6, 1]; the harmonics are computed again only when it changes.
  void setWidth(double omega);
  double omega() const { return omega_; }

  double height(double f) const { return f < omega_ ? 0.5 * (1.0 - std::cos(2.0 * kPi * f / omega_)) : 0.0; }
  // The integral of the height over [0, f].
  double heightTo(double f) const;
  double heightMean() const { return 0.5 * omega_; }
  const Harmonics& heightHarmonics() const { return height_; }

  double climb(double f, int direction) const;
  // The climb (height units) met from the start of the period to f moving +1, or, for -1, the
  // climb met going the other way (the descent along +1); climb's integral is omega / pi times it.
  double climbTo(double f, int direction) const;
  double climbMean() const { return omega_ / kPi; }
  const Harmonics& climbHarmonics(int direction) const { return direction > 0 ? climbingUp_ : climbingDown_; }
  // The harmonic from which on both the climb's and the height's fold below kNegligibleFold
  // (PatternTravel.hpp), from the bounds above.
  double sharpHarmonic() const { return sharp_; }

 private:
  double omega_ = -1.0;
  double sharp_ = 0.0;
  Harmonics climbingUp_{}, climbingDown_{}, height_{};
};

}  // namespace kf::patterns
