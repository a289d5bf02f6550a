// DeviceSpec: the numbers that describe one friction device (the "paper" profile by default),
// shared by the device thread, the simulator, record/replay and the UGens.
#pragma once

#include <string_view>

namespace kf {

struct DeviceSpec {
  double countMm = 0.021;        // one sensor count; 334 mm/s / (127 counts x 125 Hz)
  double updateRateHz = 125.0;   // HID report rate of the mouse sensor
  int maxCountsPerReport = 127;  // int8 counts per axis
  double minForceN = 0.14;       // kinetic friction with the magnet off
  double maxForceN = 1.4;
  double audioLatencyS = 0.0014;
  double tactileLatencyS = 0.0024;
  double forceFramePeriodS = 0.001;   // 1 kHz force frames
  double maxForceSlewNPerS = 2000.0;  // 1.26 N in 0.63 ms
  double watchdogS = 0.01;            // no frame for this long -> magnet off (minForceN)
  double magnetLagS = 0.0024;         // sim: first-order lag of the magnet's force
  // The coil: a hard limit on the drive level (0..1 of full-scale current), and a first-order
  // heat estimate (mean of drive^2 over heatTimeConstantS) that derates the drive towards
  // sqrt(heatRatedDuty) when it reaches heatRatedDuty, the drive^2 the coil takes for ever.
  double maxDriveLevel = 1.0;
  double heatTimeConstantS = 30.0;
  double heatRatedDuty = 0.5;

  // maxCounts * countMm * updateRate: 334 mm/s for the paper profile.
  double maxSpeedMmPerS() const { return maxCountsPerReport * countMm * updateRateHz; }
  // Audio is delayed by this much so sound and touch arrive together (paper, section 3).
  double audioDelayS() const { return tactileLatencyS - audioLatencyS; }
  double updatePeriodS() const { return 1.0 / updateRateHz; }

  // Sets the field named `key` (the member name above) to `value`. Returns false, and
  // changes nothing, for an unknown key or a value out of the field's domain.
  bool applyOverride(std::string_view key, double value);
  // True when all fields are usable together (positive rates, minForceN <= maxForceN...).
  bool isValid() const;
};

}  // namespace kf
