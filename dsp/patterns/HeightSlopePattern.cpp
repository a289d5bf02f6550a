#include "patterns/HeightSlopePattern.hpp"

namespace kf::patterns {

void BumpPattern::set(double periodMm, double widthMm, bool valleys, double anchorMm) {
  coordinate_.setPeriod(periodMm, anchorMm);
  if (widthMm > 0.0 && std::isfinite(widthMm)) widthMm_ = widthMm;
  bump_.setWidth(widthMm_ / coordinate_.periodMm());
  valleys_ = valleys;
}

double BumpPattern::level(const Travel& travel, bool antialias) const {
  const double u1 = coordinate_.cycles(travel.toMm);
  // A valley climbs where a bump descends: the bump's climb moving the other way.
  const int direction = valleys_ ? -travel.direction : travel.direction;
  if (!antialias) return bump_.climb(fractionOf(u1), direction);
  // The climb per cycle of travel, over the steepest (pi / omega): the mean of climb() over the travel.
  const double scale = bump_.climbMean();
  const double u0 = coordinate_.cycles(travel.fromMm);
  const double boxed = periodicMean(
      u0, u1, scale, [&](double f) { return scale * bump_.climbTo(f, direction); },
      [&](double f) { return bump_.climb(f, direction); });
  return bandLimitedSeries(boxed, scale, bump_.climbHarmonics(direction), u0, u1, travel, coordinate_.periodMm(),
                           bump_.sharpHarmonic());
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
