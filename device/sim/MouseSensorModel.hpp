// MouseSensorModel: the optical sensor of the simulated puck — floor-quantised counts, one
// HID report per update period, int8 clipping with loss of the excess, and optional
// imperfections (timing jitter, dropped reports, lift-off, device clock drift).
#pragma once

#include <cstdint>

#include "core/spec/DeviceSpec.hpp"
#include "core/spec/Report.hpp"
#include "sim/DeterministicRandom.hpp"
#include "sim/SimParams.hpp"

namespace kf {

class MouseSensorModel {
 public:
  MouseSensorModel(const DeviceSpec& spec, const SimParams& params, double initialPositionMm);

  // True time of the next report (nominal k / updateRateHz plus jitter), k = 1, 2, ...
  double nextReportTimeS() const { return nextReportTimeS_; }

  // Takes the report due at nextReportTimeS() from the true position then. Returns false when
  // that report is dropped (its counts go into the next delivered one, flagged kAfterLoss).
  bool takeReport(double positionMm, MouseReport& out) { return takeReport(positionMm, 0.0, out); }
  // The same on the surface: counts along x and y, each axis floor-quantised and clipped alone.
  bool takeReport(double xMm, double yMm, MouseReport& out);

  uint64_t droppedReports() const { return droppedReports_; }

 private:
  void scheduleNext();
  bool isLifted(double timeS) const;

  DeviceSpec spec_;
  SimParams params_;
  DeterministicRandom random_;
  int64_t reportIndex_ = 0;  // of the report due at nextReportTimeS_
  double nextReportTimeS_ = 0.0;
  int64_t lastQuantumCounts_;       // floor(position / countMm) at the last report
  int64_t lastQuantumYCounts_ = 0;  // the same along y (the puck starts at y = 0)
  int32_t pendingDxCounts_ = 0;
  int32_t pendingDyCounts_ = 0;
  uint32_t pendingFlags_ = 0;
  uint64_t droppedReports_ = 0;
};

}  // namespace kf
