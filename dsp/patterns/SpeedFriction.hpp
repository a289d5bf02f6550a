// Friction that depends on speed, not on place (the speed is the travel over the last frame
// over the frame period, PatternTravel.hpp):
// - viscous: the level rises linearly with speed and is full at fullSpeed (mm/s): a damping of
//   (hiForce - loForce) / fullSpeed N per mm/s up to hiForce;
// - stick-slip: a puck at rest sticks (level 1: the breakaway force, hiForce); it slips (level
//   0: the sliding force, loForce) once its speed exceeds slipSpeed, and sticks again only when
//   its speed falls below stickSpeed <= slipSpeed (the hysteresis between the two).
#pragma once

#include "patterns/PatternTravel.hpp"

namespace kf::patterns {

class ViscousFriction {
 public:
  // fullSpeed not finite and > 0 keeps the last good one.
  void set(double fullSpeedMmPerS);
  double level(const Travel& travel) const { return clampLevel(travel.speedMmPerS / fullSpeedMmPerS_); }

 private:
  double fullSpeedMmPerS_ = 100.0;
};

class StickSlipFriction {
 public:
  // Speeds not finite or negative keep the last good one; stickSpeed above slipSpeed is slipSpeed.
  void set(double slipSpeedMmPerS, double stickSpeedMmPerS);
  double level(const Travel& travel);
  bool sliding() const { return sliding_; }

 private:
  double slipSpeedMmPerS_ = 5.0;
  double stickSpeedMmPerS_ = 2.0;
  bool sliding_ = false;
};

}  // namespace kf::patterns
