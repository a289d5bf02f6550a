// DeviceSpec: the numbers that describe one friction device (the "paper" profile by default),
// shared by the device thread, the simulator, record/replay and the UGens.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "PaperProfile.hpp"

namespace kf {

struct DeviceSpec {
  // The paper's device by default (profiles/paper.json).
  double countMm = paper::device::countMm;            // one sensor count; 334 mm/s / (127 counts x 125 Hz)
  double updateRateHz = paper::device::updateRateHz;  // HID report rate of the mouse sensor
  int maxCountsPerReport = static_cast<int>(paper::device::maxCountsPerReport);  // int8 counts per axis
  double minForceN = paper::device::minForceN;                                   // kinetic friction with the magnet off
  double maxForceN = paper::device::maxForceN;
  double audioLatencyS = paper::device::audioLatencyS;
  double tactileLatencyS = paper::device::tactileLatencyS;
  double forceFramePeriodS = paper::device::forceFramePeriodS;  // 1 kHz force frames
  double maxForceSlewNPerS = paper::device::maxForceSlewNPerS;  // 1.26 N in 0.63 ms
  double watchdogS = paper::device::watchdogS;                  // no frame for this long -> magnet off (minForceN)
  double magnetLagS = paper::device::magnetLagS;                // sim: first-order lag of the magnet's force
  // The coil: a hard limit on the drive level (0..1 of full-scale current), and a first-order
  // heat estimate (mean of drive^2 over heatTimeConstantS) that derates the drive towards
  // sqrt(heatRatedDuty) when it reaches heatRatedDuty, the drive^2 the coil takes for ever.
  double maxDriveLevel = paper::device::maxDriveLevel;
  double heatTimeConstantS = paper::device::heatTimeConstantS;
  double heatRatedDuty = paper::device::heatRatedDuty;
  // The surface's axes from the mouse's (a mouse profile sets them): swapXY 1 takes the
  // surface's x from the mouse's y and its y from the mouse's x; signX, signY -1 reverse an
  // axis (after the swap); countMm and countMmY are the count sizes along the surface's x and
  // y (countMmY 0: the same as x). Applied where counts become millimetres (countsToMm).
  double countMmY = 0.0;
  double swapXY = 0.0;
  double signX = 1.0;
  double signY = 1.0;

  // maxCounts * countMm * updateRate: 334 mm/s for the paper profile.
  double maxSpeedMmPerS() const { return maxCountsPerReport * countMm * updateRateHz; }
  // Audio is delayed by this much so sound and touch arrive together (paper, section 3).
  double audioDelayS() const { return tactileLatencyS - audioLatencyS; }
  double updatePeriodS() const { return 1.0 / updateRateHz; }
  // The mouse's counts (x and y as it reports them) as millimetres along the surface's x and y.
  void countsToMm(int64_t mouseXCounts, int64_t mouseYCounts, double& xMm, double& yMm) const {
    const bool swap = swapXY != 0.0;
    xMm = signX * countMm * static_cast<double>(swap ? mouseYCounts : mouseXCounts);
    yMm = signY * (countMmY > 0.0 ? countMmY : countMm) * static_cast<double>(swap ? mouseXCounts : mouseYCounts);
  }

  // Sets the field named `key` (the member name above) to `value`. Returns false, and
  // changes nothing, for an unknown key or a value outside the field's bounds
  // (SettingBounds); `error`, if given, then names the field, the value and the range.
  bool applyOverride(std::string_view key, double value, std::string* error = nullptr);
  // True when every field is within its bounds and they fit together (minForceN <=
  // maxForceN, a watchdog longer than two frames); `error` says what does not.
  bool isValid(std::string* error = nullptr) const;
};

}  // namespace kf
