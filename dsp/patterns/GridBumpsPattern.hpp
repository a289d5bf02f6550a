// A grid of bumps in 2D felt by the height rule (issue 27 item 3): the height
//   h(x, y) = b(x) * b(y),  b(u) = (1 - cos(2 pi u / w)) / 2 on [0, w) of every spacing, 0 beyond
// (one raised-cosine bump of width w mm from (0, 0) in every cell of spacingX by spacingY mm).
// Climbing resists, going down is free, in any direction of motion, with the climb counted per
// axis: moving along the unit vector (ux, uy),
//   level = (|ux| (pi / wx) c_x(x) b(y) + |uy| b(x) (pi / wy) c_y(y)) / (pi / min(wx, wy))
// where c_axis is the one-axis bump's climb in the sign of that velocity component
// (RaisedCosineBump::climb: max(0, s sin(2 pi f / omega)), the slope over the steepest, pi / w).
// It is the directional slope max(0, u . grad h) (over the steepest slope of h, pi / w) wherever
// both axes climb or both descend (along an axis; through a bump's centre on the diagonal), and
// counts more where one climbs and the other descends (the climbing axis alone, not the net).
// Why not the directional slope: rectified, it is not separable and its 2D harmonics depend on
// the direction (no closed form); this rule is a sum of products of one-axis functions, each with
// closed-form harmonics, so it is band-limited per harmonic as the 1D patterns are. It is <= 1:
// where both axes climb it is u . grad h <= |grad h| <= pi / min(wx, wy); where one climbs, that
// axis's part of u . grad h alone.
//
// Rendered (anti-aliased) as each one-axis factor's mean over that axis's travel in the frame
// (the rule's mean over the box the travel spans in x and y; along an axis the climb factor is then
// exactly the 1D bumps' level, so the level is theirs times b across it times min(wx, wy) / wx,
// which is 1 unless the width clamps to one spacing only), band-limited per harmonic. Both factors on an axis get the
// same filter (box, spline gains, blend: a kernel >= 0 of unit mass), so the level is the rule smoothed by a kernel >=
// 0 and stays within [0, 1] with no clamp at work (no clipping to alias). The band: component (m, n) of the product has
// temporal frequency |m vx / Sx + n vy / Sy| <= |m| fx + |n| fy (fx = |vx| / Sx, fy = |vy| / Sy, Hz), so each axis gets
// its own first harmonic not kept, Kx and Ky with Kx fx + Ky fy = the frames' Nyquist frequency (500 Hz at 1 ms),
// shared as
//   Kx = N / (sqrt(fx) (sqrt(fx) + sqrt(fy))),  Ky = N / (sqrt(fy) (sqrt(fx) + sqrt(fy)))
// (Kx -> inf continuously as fx -> 0: along y the x factors are not filtered at all, and along x
// Kx = N / fx, the 1D bumps' own). Each one-axis factor is bandLimitedSeriesTo(K of its axis,
// the bump's kSharp): below K = kFull = max(kMaxHarmonics, kSharp) every component it keeps is
// below the Nyquist frequency (cut at kMaxHarmonics past it: smoother than the bump); from kFull
// on (the blend, then the closed form, PatternTravel.hpp) the box's harmonics past K are left.
// In 1D each folds below kNegligibleFold (the box is 1 / (2 kStop) cycles: its sinc <= 2 / pi at
// the Nyquist frequency); per axis in 2D the box is that axis's travel, whose sinc at m = Kx may
// reach min(1, (2 / pi)(1 + sqrt(fy / fx))): the margin is the switch at 2 kFull (a factor of 4 in
// these 1 / k^2 coefficients) and the other factor's lines (<= omega). Measured in the closed-form
// regime: 1.5e-8 to 4e-7 of the range (10 x 10 mm grids, widths 5 and 0.1 mm, fx = fy and 2 fy).
// Raw (antialias off): the rule at the current position, in the frame's direction per axis.
// The direction (ux, uy and each axis's sign) is the last travel's, held while the puck is still
// (as 1D's): a creeping or reversing puck is the rule at its point, with no division by a tiny
// travel (periodicMean's short-travel case).
#pragma once

#include "patterns/RaisedCosineBump.hpp"

namespace kf::patterns {

class GridBumpsPattern {
 public:
  // Spacings or width not finite and > 0 keep the last good one; the width is clamped to each
  // spacing. A change of spacing keeps the phase at (anchorXMm, anchorYMm).
  void set(double spacingXMm, double spacingYMm, double widthMm, double anchorXMm, double anchorYMm);
  // The level for a frame's travel: x's (with the frame period), y from y0 to y1 mm, finite (the
  // core holds a non-finite y; here it would read as the cell's origin). Before any travel, 0.
  double level(const Travel& x, double y0, double y1, bool antialias);
  double steepestSlope() const { return kPi / std::min(x_.widthMm, y_.widthMm); }

 private:
  struct Axis {
    PeriodicCoordinate coordinate;  // spacing 1 mm before the first good one (PeriodicCoordinate's)
    RaisedCosineBump bump;          // width 0.5 cycle before the first good one
    double widthMm = 0.5;           // the width as clamped to this spacing
  };
  // The climb and the height factors along one axis for its travel u0 -> u1 (cycles), moving in
  // direction s (+-1; on a still axis either: its climb is counted with weight 0), filtered to
  // kStop (inf: the box mean; antialias off: the point u1).
  struct Factors {
    double climb, height;
  };
  static Factors factors(const Axis& axis, double u0, double u1, int s, double kStop, bool antialias);

  Axis x_, y_;
  double widthMm_ = 0.5;
  double ux_ = 0.0, uy_ = 0.0;  // |direction| of the last travel: none before any (level 0)
  int sx_ = 1, sy_ = 1;         // each axis's last direction of motion
  double held_ = 0.0;           // the last finite level (a non-finite one holds it)
};

}  // namespace kf::patterns
