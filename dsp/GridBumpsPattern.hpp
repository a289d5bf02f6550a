// A grid of bumps in 2D felt by the height rule (issue 27 item 3): the height
//   h(x, y) = b(x) * b(y),  b(u) = (1 - cos(2 pi u / w)) / 2 on [0, w) of every spacing, 0 beyond
// (one raised-cosine bump of width w mm from (0, 0) in every cell of spacingX by spacingY mm),
// and the level = clip(climb along the frame's travel / its length / steepest slope, 0, 1):
// climbing resists, going down is free, in any direction of motion. The steepest slope of h is
// pi / w (crossing a bump's centre along an axis; |grad h| is no larger elsewhere), so that crossing
// gives the full level. Anti-aliased: (h(end) - h(start)) / |end - start| is the exact mean of the
// directional slope over the frame's straight travel (a box filter as long as the travel, as the
// 1D patterns' mean over the travel). Raw: the directional slope at the current position.
// Held while the travel is below kMinTravelMm (the puck at rest keeps its force).
#pragma once

#include "PatternTravel.hpp"

namespace kf::patterns {

class GridBumpsPattern {
 public:
  static constexpr double kMinTravelMm = 1e-4;  // 0.1 mm/s over a 1 ms frame, as SlopeOfHeight

  // Spacings or width not finite and > 0 keep the last good one; the width is clamped to each
  // spacing. A change of spacing keeps the phase at (anchorXMm, anchorYMm).
  void set(double spacingXMm, double spacingYMm, double widthMm, double anchorXMm, double anchorYMm);
  // The level for a frame's travel from (x0, y0) to (x1, y1) mm.
  double level(double x0, double y0, double x1, double y1, bool antialias);
  // The definition: height (bump height 1) and its gradient (per mm) at (x, y).
  double height(double xMm, double yMm) const;
  double steepestSlope() const { return kPi / std::min(widthX_, widthY_); }

 private:
  // b and db/du (per mm) along one axis.
  static double bump(const PeriodicCoordinate& axis, double omega, double uMm);
  static double bumpSlope(const PeriodicCoordinate& axis, double omega, double widthMm, double uMm);

  PeriodicCoordinate axisX_, axisY_;
  // Before the first good values: spacings 1 mm (PeriodicCoordinate's) and width 0.5 mm, as BumpPattern.
  double widthMm_ = 0.5;
  double omegaX_ = 0.5, omegaY_ = 0.5;  // width over spacing, per axis
  double widthX_ = 0.5, widthY_ = 0.5;  // the width as clamped to each spacing (mm)
  double held_ = 0.0;
};

}  // namespace kf::patterns
