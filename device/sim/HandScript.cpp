#include "sim/HandScript.hpp"

#include <cmath>

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

HandScript HandScript::constantForce(double forceN) {
  HandScript script;
  script.kind = Kind::kConstantForce;
  script.constantForceN = forceN;
  return script;
}

bool HandScript::isValid() const {
  auto within = [](const char* name, double value) { return isWithinBounds(*findSettingBounds(name), value); };
  if (kind == Kind::kConstantForce) return within("handForceN", constantForceN);
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
    pathMm_ = script.points;
  } else if (kind_ == HandScript::Kind::kSpeeds) {
    double timeS = 0.0;
    double positionMm = 0.0;
    pathMm_.emplace_back(timeS, positionMm);
    for (const auto& [speedMmPerS, durationS] : script.points) {
      timeS += durationS;
      positionMm += speedMmPerS * durationS;
      pathMm_.emplace_back(timeS, positionMm);
    }
  }
}

HandTarget HandTrajectory::at(double timeS) const {
  if (pathMm_.empty()) return {};
  if (timeS <= pathMm_.front().first) return {pathMm_.front().second, 0.0};
  if (timeS >= pathMm_.back().first) return {pathMm_.back().second, 0.0};
  if (cursor_ + 1 >= pathMm_.size() || pathMm_[cursor_].first > timeS) cursor_ = 0;
  while (pathMm_[cursor_ + 1].first < timeS) ++cursor_;
  const auto& [t0, x0] = pathMm_[cursor_];
  const auto& [t1, x1] = pathMm_[cursor_ + 1];
  const double durationS = t1 - t0;
  if (durationS <= 0.0) return {x1, 0.0};
  const double speedMmPerS = (x1 - x0) / durationS;
  return {x0 + speedMmPerS * (timeS - t0), speedMmPerS};
}

}  // namespace kf
