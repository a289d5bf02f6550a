// ForceSafety: every force frame passes here before it reaches a ForceBackend, so the magnet
// is never driven outside the device range, by NaN, too fast, or left on when frames stop.
#pragma once

#include "DeviceSpec.hpp"
#include "Report.hpp"

namespace kf {

class ForceSafety {
 public:
  explicit ForceSafety(const DeviceSpec& spec);

  // Makes a requested frame safe: NaN/Inf -> minForceN, clamp to [minForceN, maxForceN],
  // then slew limit. A frame may move by maxForceSlewNPerS times the time since the previous
  // frame (frame clock), and by at least one frame period's worth, since each frame stands
  // for the mean over one period. `arrivalS` (device clock) feeds the watchdog.
  // Returns the force to command.
  float applyFrame(const ForceFrame& frame, double arrivalS);

  // True exactly once when frames stopped: none arrived for watchdogS (device clock) since
  // the last one. The force is then minForceN and the caller drives the magnet off. The next
  // frame re-arms it.
  bool checkWatchdog(double nowS);

  // The magnet was driven off (close, trip): the next frame slews up from minForceN.
  void resetToOff();

  float commandedForceN() const { return commandedForceN_; }

 private:
  DeviceSpec spec_;
  float commandedForceN_;
  double lastFrameTimeS_ = 0.0;
  double lastArrivalS_ = 0.0;
  bool haveFrame_ = false;
  bool watchdogArmed_ = false;
};

}  // namespace kf
