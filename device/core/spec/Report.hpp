// Report: what crosses between the device thread and the audio thread — mouse reports one
// way (counts with a device timestamp), force frames the other way.
#pragma once

#include <cstdint>
#include <limits>

namespace kf {

enum ReportFlag : uint32_t {
  kSaturated = 1,  // counts were clipped to +-maxCountsPerReport; the excess is lost
  kAfterLoss = 2,  // reports before this one were dropped; counts accumulate over them
  kLifted = 4,     // the sensor lost the surface; no counts
};

struct MouseReport {
  double deviceTimeS = 0.0;  // the device's clock, not audio time
  int32_t dxCounts = 0;
  int32_t dyCounts = 0;
  uint32_t buttons = 0;    // bit i = button i + 1
  uint32_t flags = 0;      // ReportFlag bits
  double hostTimeS = 0.0;  // set by Device: its clock when the device thread took the report
  // Set by Device: the puck's position after this report, in counts since the device opened.
  // Every reader of the device derives its position from these, so a reader that starts late
  // or misses reports (a full queue) still agrees with the others.
  int64_t xCounts = 0;
  int64_t yCounts = 0;
};

// One 1 ms frame: the mean force requested over it.
struct ForceFrame {
  double timeS = 0.0;
  float forceN = 0.0f;
  // The device clock (Device::nowS) when the frame's millisecond ended, as the audio side
  // estimates it; NaN when unknown. Measures the force latency in realtime.
  double endedHostS = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace kf
