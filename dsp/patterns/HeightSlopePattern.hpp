// Bumps and valleys felt as height: the force follows the slope of a height profile in the
// direction of motion. Climbing resists, in proportion to the slope; going down is free (the
// minimum force), so a bump resists on its way up from either side and reads as a bump, where a
// detent (DetentPattern) resists the same way whichever way it is left.
//
// BumpPattern: one raised-cosine bump (or valley) of width w in every period p, from x = 0:
//   h(u) = (1 - cos(2 pi u / omega)) / 2 on [0, omega), 0 on [omega, 1);  omega = w / p
// (a valley is -h). Level = the climb in the direction of motion per unit travel, over the
// steepest slope (pi / omega per period), so the steepest climb is 1. Rendered as its mean over
// the frame's travel: the climb over the travel (closed form) over the travel, band-limited to
// the speed with its harmonics. The bump's height, climb and harmonics are RaisedCosineBump's; a
// valley climbs where a bump descends: the bump's climb moving the other way.
//
// SlopeOfHeight: the same rule on any height signal of the position (a buffer read by
// SpatialBufRd): level = (height now - height one frame ago) / |travel| / fullSlope, within
// [0, 1]; held while the travel is below kMinTravelMm (the puck at rest keeps its force).
#pragma once

#include "patterns/RaisedCosineBump.hpp"

namespace kf::patterns {

class BumpPattern {
 public:
  // Period or width not finite and > 0 keep the last good one; the width is clamped
  // to (0, period]. valleys: valleys instead of bumps. A change of period keeps the phase at
  // anchorMm.
  void set(double periodMm, double widthMm, bool valleys, double anchorMm);
  double level(const Travel& travel, bool antialias) const;

 private:
  PeriodicCoordinate coordinate_;
  RaisedCosineBump bump_;
  double widthMm_ = 0.5;
  bool valleys_ = false;
};

class SlopeOfHeight {
 public:
  static constexpr double kMinTravelMm = 1e-4;  // 0.1 mm/s over a 1 ms frame

  // fullSlope (height units per mm) that gives the full level; not finite and > 0 keeps the last.
  void setFullSlope(double fullSlope);
  double level(const Travel& travel, double heightFrom, double heightTo);

 private:
  double fullSlope_ = 1.0;
  double held_ = 0.0;
};

}  // namespace kf::patterns
