// ForceSafety: every force frame passes here before it reaches a ForceBackend, so the magnet
// is never driven outside the device range, by NaN, too fast, too hard, too long, or left on
// when frames stop. The path, in this order:
//   1. NaN/Inf -> minForceN   2. clamp to [minForceN, maxForceN]   3. slew limit
//   4. calibration: N -> drive level (0..1)   5. hard limit maxDriveLevel
//   6. heat estimate (mean drive^2 over heatTimeConstantS) that derates the drive
// The force reported as commanded is what the drive gives by the calibration, so limits 5 and
// 6 show in it (and in FrictionOut's output).
#pragma once

#include "core/force/CalibrationTable.hpp"
#include "core/spec/DeviceSpec.hpp"
#include "core/spec/Report.hpp"

namespace kf {

class ForceSafety {
 public:
  explicit ForceSafety(const DeviceSpec& spec);

  // Makes a requested frame safe (steps 1-6 above). A frame may move by maxForceSlewNPerS
  // times the time since the previous frame (frame clock), and by at least one frame period's
  // worth, since each frame stands for the mean over one period. `arrivalS` (device clock)
  // feeds the watchdog. Returns the force to command; driveLevel() is its drive.
  float applyFrame(const ForceFrame& frame, double arrivalS);

  // True exactly once when frames stopped: none arrived for watchdogS (device clock) since
  // the last one. The force is then minForceN and the caller drives the magnet off. The next
  // frame re-arms it.
  bool checkWatchdog(double nowS);

  // The magnet was driven off (close, trip): the next frame slews up from minForceN.
  void resetToOff();
  // Goes on from `previous`, the path this one replaces on the same coil (a reloaded
  // calibration): its heat, its slew and its last drive. `driveScale` turns the previous drive
  // levels into this one's (the ratio of their full-scale currents), so the heat stays the
  // coil's mean current squared.
  void continueFrom(const ForceSafety& previous, double driveScale);

  // Replaces the calibration (default: linear from minForceN at drive 0 to maxForceN at 1).
  // Allocates: not from the audio thread.
  void setCalibration(const CalibrationTable& table) { calibration_ = table; }
  const CalibrationTable& calibration() const { return calibration_; }

  float commandedForceN() const { return commandedForceN_; }
  float driveLevel() const { return driveLevel_; }
  // The heat estimate (mean drive^2) and the drive limit it sets now.
  double heat() const { return heat_; }
  double heatDriveLimit() const;
  // Frames whose drive steps 5 or 6 lowered.
  uint64_t driveLimitedFrames() const { return driveLimitedFrames_; }

 private:
  DeviceSpec spec_;
  CalibrationTable calibration_;
  float commandedForceN_;
  float driveLevel_ = 0.0f;
  double slewedN_;  // after step 3: the slew limit works on the requested force
  double lastFrameTimeS_ = 0.0;
  double lastArrivalS_ = 0.0;
  double heat_ = 0.0;
  uint64_t driveLimitedFrames_ = 0;
  bool haveFrame_ = false;
  bool watchdogArmed_ = false;
};

}  // namespace kf
