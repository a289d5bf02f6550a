// HandScript: what the simulated hand wants to do — follow a path of (time, position) points
// along x, a series of speed segments along x, a path of (time, x, y) points on the surface (and
// the 2D scripts made of one: a line at an angle, a circle, a raster), or push with a constant
// force along x (for tests), or explore a strip as a participant would (ExploringHand: a push,
// not a path, so friction slows it).
#pragma once

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include "sim/ExploringHand.hpp"

namespace kf {

struct HandScript {
  enum class Kind { kNone = -1, kPath = 0, kSpeeds = 1, kConstantForce = 2, kPath2D = 3, kExplore = 7 };

  Kind kind = Kind::kNone;
  // kPath: (timeS, xMm), time ascending; linear in between, held before the first and after
  //        the last point.
  // kSpeeds: (speedMmPerS, durationS) segments integrated from x = 0 at t = 0; held after.
  std::vector<std::pair<double, double>> points;
  double constantForceN = 0.0;  // kConstantForce
  // kPath2D: (timeS, xMm, yMm), time ascending; linear in between, held before and after.
  std::vector<std::array<double, 3>> points2D;
  ExploreSettings explore;  // kExplore

  static HandScript path(std::vector<std::pair<double, double>> timeAndPositionMm);
  static HandScript speeds(std::vector<std::pair<double, double>> speedAndDurationS);
  static HandScript constantForce(double forceN);
  static HandScript none() { return {}; }
  static HandScript path2D(std::vector<std::array<double, 3>> timeXYMm);
  // The 2D scripts, each a path2D at a constant speed (mm/s) from t = 0. An argument that makes
  // no path (speed <= 0, a count out of its range, non-finite) gives a script isValid() refuses.
  // From (x0, y0) for lengthMm at angleDeg (counter-clockwise from +x).
  static HandScript line(double x0Mm, double y0Mm, double angleDeg, double lengthMm, double speedMmPerS);
  // `turns` turns (1..1000) counter-clockwise around (cx, cy) from angle 0 (cx + radius, cy), as
  // kCircleSegments chords per turn.
  static HandScript circle(double cxMm, double cyMm, double radiusMm, double speedMmPerS, double turns);
  // `rows` rows (1..1000) of widthMm along +x, the first at (x0, y0), then -x, and so on, each
  // heightMm / (rows - 1) further along y (a boustrophedon, as a hand scans a page).
  static HandScript raster(double x0Mm, double y0Mm, double widthMm, double heightMm, double rows, double speedMmPerS);
  static constexpr int kCircleSegments = 64;
  // A participant exploring the strip [fromMm, toMm] (ExploringHand); a script isValid()
  // refuses when the settings are not ExploreSettings::isValid().
  static HandScript exploring(const ExploreSettings& settings);

  // True when the points are usable: within their bounds (SettingBounds: handTimeS,
  // handPositionMm, handSpeedMmPerS, handDurationS, handForceN), times ascending, and a 2D
  // script made of at least one point.
  bool isValid() const;
};

// Where the hand's target is and how fast it moves at a time.
struct HandTarget {
  double positionMm = 0.0;  // x
  double speedMmPerS = 0.0;
  double yMm = 0.0;
  double speedYMmPerS = 0.0;
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
  std::vector<std::array<double, 3>> pathMm_;  // (timeS, xMm, yMm)
  double constantForceN_;
  mutable size_t cursor_ = 0;  // last segment used; time mostly moves forwards
};

}  // namespace kf
