// Helpers shared by the simulator tests: collecting reports from a SimDevice.
#pragma once

#include <vector>

#include "sim/SimDevice.hpp"

namespace kf::test {

// Runs the sim to untilS (host time) and returns every report made on the way.
inline std::vector<MouseReport> collectReports(SimDevice& sim, double untilS, double pollPeriodS = 0.01) {
  std::vector<MouseReport> reports;
  MouseReport buffer[64];
  for (double timeS = pollPeriodS; timeS <= untilS + 1e-9; timeS += pollPeriodS) {
    int n = 0;
    while ((n = sim.pollReports(timeS, buffer, 64)) > 0) reports.insert(reports.end(), buffer, buffer + n);
  }
  return reports;
}

}  // namespace kf::test
