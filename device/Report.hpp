// Report: what crosses between the device thread and the audio thread — mouse reports one
// way (counts with a device timestamp), force frames the other way.
#pragma once

#include <cstdint>

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
  uint32_t buttons = 0;  // bit i = button i + 1
  uint32_t flags = 0;    // ReportFlag bits
};

// One 1 ms frame: the mean force requested over it.
struct ForceFrame {
  double timeS = 0.0;
  float forceN = 0.0f;
};

}  // namespace kf
