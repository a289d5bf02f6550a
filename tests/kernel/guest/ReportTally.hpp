// ReportTally: what a backend handed on, summed: counts, reports, flags and each change of the
// buttons in order, for comparison with what was injected.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/MouseBackend.hpp"

namespace kf::guest {

struct ReportTally {
  int64_t dxCounts = 0, dyCounts = 0;
  uint64_t reports = 0, afterLoss = 0, saturated = 0;
  uint32_t buttons = 0;               // as the last report left them
  std::vector<uint32_t> buttonSteps;  // every new button state, in order
  std::vector<MouseReport> all;       // every report, in order

  void take(const MouseReport& report) {
    dxCounts += report.dxCounts;
    dyCounts += report.dyCounts;
    ++reports;
    if (report.flags & kAfterLoss) ++afterLoss;
    if (report.flags & kSaturated) ++saturated;
    if (report.buttons != buttons) buttonSteps.push_back(report.buttons);
    buttons = report.buttons;
    all.push_back(report);
  }
  // Everything the backend has queued so far; how many reports that was.
  int drain(MouseBackend& backend) {
    MouseReport batch[256];
    int total = 0;
    for (int n; (n = backend.pollReports(1e300, batch, 256)) > 0; total += n)
      for (int i = 0; i < n; ++i) take(batch[i]);
    return total;
  }
  std::string summary() const {
    return "dx " + std::to_string(dxCounts) + ", dy " + std::to_string(dyCounts) + ", " + std::to_string(reports) +
           " reports, " + std::to_string(buttonSteps.size()) + " button changes";
  }
};

}  // namespace kf::guest
