#include "GridBumpsPattern.hpp"

namespace kf::patterns {

void GridBumpsPattern::set(double spacingXMm, double spacingYMm, double widthMm, double anchorXMm, double anchorYMm) {
  axisX_.setPeriod(spacingXMm, anchorXMm);
  axisY_.setPeriod(spacingYMm, anchorYMm);
  if (widthMm > 0.0 && std::isfinite(widthMm)) widthMm_ = widthMm;
  omegaX_ = std::clamp(widthMm_ / axisX_.periodMm(), 1e-6, 1.0);
  omegaY_ = std::clamp(widthMm_ / axisY_.periodMm(), 1e-6, 1.0);
  widthX_ = omegaX_ * axisX_.periodMm();
  widthY_ = omegaY_ * axisY_.periodMm();
}

double GridBumpsPattern::bump(const PeriodicCoordinate& axis, double omega, double uMm) {
  const double f = fractionOf(axis.cycles(uMm));
  return f < omega ? 0.5 * (1.0 - std::cos(2.0 * kPi * f / omega)) : 0.0;
}

double GridBumpsPattern::bumpSlope(const PeriodicCoordinate& axis, double omega, double widthMm, double uMm) {
  const double f = fractionOf(axis.cycles(uMm));
  return f < omega ? kPi / widthMm * std::sin(2.0 * kPi * f / omega) : 0.0;
}

double GridBumpsPattern::height(double xMm, double yMm) const {
  return bump(axisX_, omegaX_, xMm) * bump(axisY_, omegaY_, yMm);
}

double GridBumpsPattern::level(double x0, double y0, double x1, double y1, bool antialias) {
  const double dx = x1 - x0, dy = y1 - y0, travelMm = std::hypot(dx, dy);
  if (!(travelMm >= kMinTravelMm)) return held_;
  double slope;  // height units per mm along the travel
  if (antialias) {
    slope = (height(x1, y1) - height(x0, y0)) / travelMm;
  } else {
    const double gx = bumpSlope(axisX_, omegaX_, widthX_, x1) * bump(axisY_, omegaY_, y1);
    const double gy = bump(axisX_, omegaX_, x1) * bumpSlope(axisY_, omegaY_, widthY_, y1);
    slope = (gx * dx + gy * dy) / travelMm;
  }
  if (!std::isfinite(slope)) return held_;
  return held_ = clampLevel(slope / steepestSlope());
}

}  // namespace kf::patterns
