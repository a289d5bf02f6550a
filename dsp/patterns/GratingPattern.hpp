// A grating: alternating high and low resistance along the surface (roughness). Per period
// (cycles u in [0, 1) from x = 0): a rise over the edge width e, high, a fall over e, low. The
// duty d is the high part measured at half height, so the level is
//   u/e on [0, e),  1 on [e, d),  1 - (u - d)/e on [d, d + e),  0 on [d + e, 1)
// with e (as a fraction of the period) at most min(d, 1 - d). Rendered as its mean over the
// frame's travel (closed form), band-limited to the speed (PatternTravel.hpp). Its harmonics: a
// square wave of width d centred on (d + e) / 2, convolved with a box of width e:
//   C_k = e^(-i pi k (d + e)) sin(pi k d) / (pi k) sinc(pi k e),
// so |C_k| <= 1 / (pi k) (a hard edge) and <= 1 / (pi^2 e k^2); 0 for a duty of 0 or 1 (its
// sharpness, PatternTravel.hpp's sharpHarmonic: the smaller of the two bounds' kSharp).
#pragma once

#include "patterns/PatternTravel.hpp"

namespace kf::patterns {

class GratingPattern {
 public:
  // Bad values keep the last good one: period not finite and > 0; duty, edge not finite. Duty is
  // clamped to [0, 1] and the edge to [0, min(duty, 1 - duty)] periods. A change of period keeps
  // the phase at anchorMm (the puck).
  void set(double periodMm, double duty, double edgeMm, double anchorMm);
  double level(const Travel& travel, bool antialias) const;
  // The definition at cycle fraction f in [0, 1), and its integral over [0, f].
  double at(double f) const;
  double integralTo(double f) const;
  double mean() const { return duty_; }
  double sharpHarmonic() const { return sharp_; }  // PatternTravel.hpp's kSharp

 private:
  PeriodicCoordinate coordinate_;
  double duty_ = 0.5;
  double edge_ = 0.0;  // in periods
  double edgeMm_ = 0.0;
  Harmonics harmonics_{};
  double sharp_ = 0.0;                                  // sharpHarmonic of harmonics_
  double harmonicsDuty_ = -1.0, harmonicsEdge_ = -1.0;  // what harmonics_ were computed for
};

}  // namespace kf::patterns
