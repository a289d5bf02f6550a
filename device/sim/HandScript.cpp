#include "sim/HandScript.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "core/spec/SettingBounds.hpp"

namespace kf {

HandScript HandScript::path(std::vector<std::pair<double, double>> timeAndPositionMm) {
  HandScript script;
  script.kind = Kind::kPath;
  script.points = std::move(timeAndPositionMm);
  return script;
}

HandScript HandScript::speeds(std::vector<std::pair<double, double>> speedAndDurationS) {
  HandScript script;
  script.kind = Kind::kSpeeds;
  script.points = std::move(speedAndDurationS);
  return script;
}

HandScript HandScript::path2D(std::vector<std::array<double, 3>> timeXYMm) {
  HandScript script;
  script.kind = Kind::kPath2D;
  script.points2D = std::move(timeXYMm);
  return script;
}

namespace {

constexpr double kPi = 3.14159265358979323846;

// A script isValid() refuses: a 2D path with no point.
HandScript unusable2D() { return HandScript::path2D({}); }

bool finite(std::initializer_list<double> values) {
  for (double v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace

HandScript HandScript::line(double x0Mm, double y0Mm, double angleDeg, double lengthMm, double speedMmPerS) {
  if (!finite({x0Mm, y0Mm, angleDeg, lengthMm, speedMmPerS}) || !(speedMmPerS > 0.0) || lengthMm < 0.0)
    return unusable2D();
  const double a = angleDeg * kPi / 180.0;
  return path2D(
      {{0.0, x0Mm, y0Mm}, {lengthMm / speedMmPerS, x0Mm + lengthMm * std::cos(a), y0Mm + lengthMm * std::sin(a)}});
}

HandScript HandScript::circle(double cxMm, double cyMm, double radiusMm, double speedMmPerS, double turns) {
  if (!finite({cxMm, cyMm, radiusMm, speedMmPerS, turns}) || !(speedMmPerS > 0.0) || !(radiusMm >= 0.0) ||
      !(turns > 0.0 && turns <= 1000.0))
    return unusable2D();
  const auto segments = static_cast<int>(std::ceil(turns * kCircleSegments));
  const double turnS = 2.0 * kPi * radiusMm / speedMmPerS;  // the time of a turn at this speed
  std::vector<std::array<double, 3>> points;
  points.reserve(static_cast<size_t>(segments) + 1);
  for (int k = 0; k <= segments; ++k) {
    const double turn = std::min(turns, static_cast<double>(k) / kCircleSegments);
    const double a = 2.0 * kPi * turn;
    points.push_back({turn * turnS, cxMm + radiusMm * std::cos(a), cyMm + radiusMm * std::sin(a)});
  }
  return path2D(std::move(points));
}

HandScript HandScript::raster(double x0Mm, double y0Mm, double widthMm, double heightMm, double rows,
                              double speedMmPerS) {
  if (!finite({x0Mm, y0Mm, widthMm, heightMm, rows, speedMmPerS}) || !(speedMmPerS > 0.0) ||
      !(rows >= 1.0 && rows <= 1000.0) || rows != std::floor(rows))
    return unusable2D();
  const int n = static_cast<int>(rows);
  const double stepMm = n > 1 ? heightMm / (n - 1) : 0.0;
  std::vector<std::array<double, 3>> points;
  points.reserve(static_cast<size_t>(2 * n));
  double t = 0.0;
  for (int r = 0; r < n; ++r) {
    const double y = y0Mm + r * stepMm;
    const double from = r % 2 == 0 ? x0Mm : x0Mm + widthMm, to = r % 2 == 0 ? x0Mm + widthMm : x0Mm;
    if (r > 0) t += std::fabs(stepMm) / speedMmPerS;  // down to the next row
    points.push_back({t, from, y});
    t += std::fabs(widthMm) / speedMmPerS;
    points.push_back({t, to, y});
  }
  return path2D(std::move(points));
}

HandScript HandScript::constantForce(double forceN) {
  HandScript script;
  script.kind = Kind::kConstantForce;
  script.constantForceN = forceN;
  return script;
}

HandScript HandScript::exploring(const ExploreSettings& settings) {
  HandScript script;
  script.kind = Kind::kExplore;
  script.explore = settings;
  return script;
}

bool HandScript::isValid() const {
  if (kind == Kind::kExplore) return explore.isValid();
  auto within = [](const char* name, double value) { return isWithinBounds(*findSettingBounds(name), value); };
  if (kind == Kind::kConstantForce) return within("handForceN", constantForceN);
  if (kind == Kind::kPath2D) {
    for (size_t i = 0; i < points2D.size(); ++i) {
      const auto& [t, x, y] = points2D[i];
      if (!within("handTimeS", t) || !within("handPositionMm", x) || !within("handPositionMm", y)) return false;
      if (i > 0 && t < points2D[i - 1][0]) return false;
    }
    return !points2D.empty();
  }
  // Bounded values keep the integrated speed path (at most 1e5 mm/s for 1e6 s) finite.
  for (size_t i = 0; i < points.size(); ++i) {
    const auto& [a, b] = points[i];
    if (kind == Kind::kPath && (!within("handTimeS", a) || !within("handPositionMm", b))) return false;
    if (kind == Kind::kSpeeds && (!within("handSpeedMmPerS", a) || !within("handDurationS", b))) return false;
    if (kind == Kind::kPath && i > 0 && a < points[i - 1].first) return false;
  }
  return true;
}

HandTrajectory::HandTrajectory(const HandScript& script) : kind_(script.kind), constantForceN_(script.constantForceN) {
  if (kind_ == HandScript::Kind::kPath) {
    for (const auto& [t, x] : script.points) pathMm_.push_back({t, x, 0.0});
  } else if (kind_ == HandScript::Kind::kPath2D) {
    pathMm_ = script.points2D;
  } else if (kind_ == HandScript::Kind::kSpeeds) {
    double timeS = 0.0;
    double positionMm = 0.0;
    pathMm_.push_back({timeS, positionMm, 0.0});
    for (const auto& [speedMmPerS, durationS] : script.points) {
      timeS += durationS;
      positionMm += speedMmPerS * durationS;
      pathMm_.push_back({timeS, positionMm, 0.0});
    }
  }
}

HandTarget HandTrajectory::at(double timeS) const {
  if (pathMm_.empty()) return {};
  if (timeS <= pathMm_.front()[0]) return {pathMm_.front()[1], 0.0, pathMm_.front()[2], 0.0};
  if (timeS >= pathMm_.back()[0]) return {pathMm_.back()[1], 0.0, pathMm_.back()[2], 0.0};
  if (cursor_ + 1 >= pathMm_.size() || pathMm_[cursor_][0] > timeS) cursor_ = 0;
  while (pathMm_[cursor_ + 1][0] < timeS) ++cursor_;
  const auto& [t0, x0, y0] = pathMm_[cursor_];
  const auto& [t1, x1, y1] = pathMm_[cursor_ + 1];
  const double durationS = t1 - t0;
  if (durationS <= 0.0) return {x1, 0.0, y1, 0.0};
  const double speedMmPerS = (x1 - x0) / durationS, speedYMmPerS = (y1 - y0) / durationS;
  return {x0 + speedMmPerS * (timeS - t0), speedMmPerS, y0 + speedYMmPerS * (timeS - t0), speedYMmPerS};
}

}  // namespace kf
