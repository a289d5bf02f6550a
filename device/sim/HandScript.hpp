// HandScript: what the simulated hand wants to do along x — follow a path of (time, position)
// points, a series of speed segments, or push with a constant force (for tests).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace kf {

struct HandScript {
  enum class Kind { kNone = -1, kPath = 0, kSpeeds = 1, kConstantForce = 2 };

  Kind kind = Kind::kNone;
  // kPath: (timeS, xMm), time ascending; linear in between, held before the first and after
  //        the last point.
  // kSpeeds: (speedMmPerS, durationS) segments integrated from x = 0 at t = 0; held after.
  std::vector<std::pair<double, double>> points;
  double constantForceN = 0.0;  // kConstantForce

  static HandScript path(std::vector<std::pair<double, double>> timeAndPositionMm);
  static HandScript speeds(std::vector<std::pair<double, double>> speedAndDurationS);
  static HandScript constantForce(double forceN);
  static HandScript none() { return {}; }

  // True when the points are usable: within their bounds (SettingBounds: handTimeS,
  // handPositionMm, handSpeedMmPerS, handDurationS, handForceN), times ascending.
  bool isValid() const;
};

// Where the hand's target is and how fast it moves at a time.
struct HandTarget {
  double positionMm = 0.0;
  double speedMmPerS = 0.0;
};

// Evaluates a HandScript. Speed segments are turned into a path once at construction, so
// evaluation never allocates.
class HandTrajectory {
 public:
  explicit HandTrajectory(const HandScript& script);
  HandTarget at(double timeS) const;
  bool isForce() const { return kind_ == HandScript::Kind::kConstantForce; }
  bool isIdle() const { return kind_ == HandScript::Kind::kNone; }
  double constantForceN() const { return constantForceN_; }

 private:
  HandScript::Kind kind_;
  std::vector<std::pair<double, double>> pathMm_;  // (timeS, xMm)
  double constantForceN_;
  mutable size_t cursor_ = 0;  // last segment used; time mostly moves forwards
};

}  // namespace kf
