#include "SimParams.hpp"

#include <cmath>
#include <limits>

namespace kf {

bool SimParams::applyOverride(std::string_view key, double value) {
  if (!std::isfinite(value)) return false;
  auto setPositive = [value](double& field) {
    if (value <= 0.0) return false;
    field = value;
    return true;
  };
  auto setNonNegative = [value](double& field) {
    if (value < 0.0) return false;
    field = value;
    return true;
  };
  if (key == "handStiffnessNPerM") return setNonNegative(handStiffnessNPerM);
  if (key == "handDampingNSPerM") return setNonNegative(handDampingNSPerM);
  if (key == "handMaxForceN") return setNonNegative(handMaxForceN);
  if (key == "puckMassKg") return setPositive(puckMassKg);
  if (key == "stepS") return value <= 0.01 && setPositive(stepS);
  if (key == "reportJitterS") return setNonNegative(reportJitterS);
  if (key == "dropProbability") return value <= 1.0 && setNonNegative(dropProbability);
  if (key == "clockDriftPpm") {
    if (std::fabs(value) > 1e5) return false;
    clockDriftPpm = value;
    return true;
  }
  if (key == "seed") {
    if (value < 0.0 || value != std::floor(value)) return false;
    seed = static_cast<uint64_t>(value);
    return true;
  }
  if (key == "liftStartS") {
    if (value < 0.0) return false;
    liftIntervalsS.emplace_back(value, std::numeric_limits<double>::infinity());
    return true;
  }
  if (key == "liftEndS") {
    if (liftIntervalsS.empty() || value < liftIntervalsS.back().first) return false;
    liftIntervalsS.back().second = value;
    return true;
  }
  return false;
}

}  // namespace kf
