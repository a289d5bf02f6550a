#include "patterns/GridBumpsPattern.hpp"

namespace kf::patterns {

void GridBumpsPattern::set(double spacingXMm, double spacingYMm, double widthMm, double anchorXMm, double anchorYMm) {
  x_.coordinate.setPeriod(spacingXMm, anchorXMm);
  y_.coordinate.setPeriod(spacingYMm, anchorYMm);
  if (widthMm > 0.0 && std::isfinite(widthMm)) widthMm_ = widthMm;
  for (Axis* axis : {&x_, &y_}) {
    axis->bump.setWidth(widthMm_ / axis->coordinate.periodMm());
    axis->widthMm = axis->bump.omega() * axis->coordinate.periodMm();
  }
}

GridBumpsPattern::Factors GridBumpsPattern::factors(const Axis& axis, double u0, double u1, int s, double kStop,
                                                    bool antialias) {
  const RaisedCosineBump& b = axis.bump;
  if (!antialias) return {b.climb(fractionOf(u1), s), b.height(fractionOf(u1))};
  const double climbMean = b.climbMean(), heightMean = b.heightMean();
  const double climbBoxed = periodicMean(
      u0, u1, climbMean, [&](double f) { return climbMean * b.climbTo(f, s); },
      [&](double f) { return b.climb(f, s); });
  const double heightBoxed = periodicMean(
      u0, u1, heightMean, [&](double f) { return b.heightTo(f); }, [&](double f) { return b.height(f); });
  // Both in one pass: they share the travel, so the per-harmonic rotations, gains and sinc.
  const auto [climb, height] = bandLimitedSeriesTo<2>(
      kStop, b.sharpHarmonic(),
      {PeriodicLevel{climbBoxed, climbMean, &b.climbHarmonics(s)}, {heightBoxed, heightMean, &b.heightHarmonics()}}, u0,
      u1);
  return {climb, height};
}

double GridBumpsPattern::level(const Travel& x, double y0, double y1, bool antialias) {
  const double dx = x.toMm - x.fromMm, dy = y1 - y0, travelMm = std::hypot(dx, dy);
  // The direction of the last travel, held while the puck is still (as 1D's Travel::direction):
  // a creeping or reversing puck gets the rule at its point in that direction, not a held level.
  if (travelMm > 0.0) {
    ux_ = std::fabs(dx) / travelMm, uy_ = std::fabs(dy) / travelMm;
    if (dx != 0.0) sx_ = dx > 0.0 ? 1 : -1;
    if (dy != 0.0) sy_ = dy > 0.0 ? 1 : -1;
  }
  // Each axis's share of the frames' Nyquist frequency (the header): 1 / 0 = inf on a still axis.
  const double rootX = std::sqrt(std::fabs(dx) / x.framePeriodS / x_.coordinate.periodMm());
  const double rootY = std::sqrt(std::fabs(dy) / x.framePeriodS / y_.coordinate.periodMm());
  const double nyquistHz = 0.5 / x.framePeriodS;
  const Factors fx = factors(x_, x_.coordinate.cycles(x.fromMm), x_.coordinate.cycles(x.toMm), sx_,
                             nyquistHz / (rootX * (rootX + rootY)), antialias);
  const Factors fy = factors(y_, y_.coordinate.cycles(y0), y_.coordinate.cycles(y1), sy_,
                             nyquistHz / (rootY * (rootX + rootY)), antialias);
  const double level =
      (ux_ * (kPi / x_.widthMm) * fx.climb * fy.height + uy_ * (kPi / y_.widthMm) * fx.height * fy.climb) /
      steepestSlope();
  if (!std::isfinite(level)) return held_;
  return held_ = clampLevel(level);
}

}  // namespace kf::patterns
