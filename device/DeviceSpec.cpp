#include "DeviceSpec.hpp"

#include <cmath>

namespace kf {

namespace {
bool isPositive(double value) { return std::isfinite(value) && value > 0.0; }
bool isNonNegative(double value) { return std::isfinite(value) && value >= 0.0; }
bool isFraction(double value) { return std::isfinite(value) && value > 0.0 && value <= 1.0; }
}  // namespace

bool DeviceSpec::applyOverride(std::string_view key, double value) {
  if (!std::isfinite(value)) return false;
  struct Entry {
    std::string_view name;
    double DeviceSpec::*field;
    bool (*valid)(double);
  };
  static const Entry entries[] = {
      {"countMm", &DeviceSpec::countMm, isPositive},
      {"updateRateHz", &DeviceSpec::updateRateHz, isPositive},
      {"minForceN", &DeviceSpec::minForceN, isNonNegative},
      {"maxForceN", &DeviceSpec::maxForceN, isNonNegative},
      {"audioLatencyS", &DeviceSpec::audioLatencyS, isNonNegative},
      {"tactileLatencyS", &DeviceSpec::tactileLatencyS, isNonNegative},
      {"forceFramePeriodS", &DeviceSpec::forceFramePeriodS, isPositive},
      {"maxForceSlewNPerS", &DeviceSpec::maxForceSlewNPerS, isPositive},
      {"watchdogS", &DeviceSpec::watchdogS, isPositive},
      {"magnetLagS", &DeviceSpec::magnetLagS, isNonNegative},
      {"maxDriveLevel", &DeviceSpec::maxDriveLevel, isFraction},
      {"heatTimeConstantS", &DeviceSpec::heatTimeConstantS, isPositive},
      {"heatRatedDuty", &DeviceSpec::heatRatedDuty, isFraction},
  };
  for (const Entry& entry : entries) {
    if (entry.name == key) {
      if (!entry.valid(value)) return false;
      this->*entry.field = value;
      return true;
    }
  }
  if (key == "maxCountsPerReport") {
    if (value < 1.0 || value > 32767.0 || value != std::floor(value)) return false;
    maxCountsPerReport = static_cast<int>(value);
    return true;
  }
  return false;
}

bool DeviceSpec::isValid() const {
  return isPositive(countMm) && isPositive(updateRateHz) && maxCountsPerReport >= 1 && isNonNegative(minForceN) &&
         isNonNegative(maxForceN) && minForceN <= maxForceN && isNonNegative(audioLatencyS) &&
         isNonNegative(tactileLatencyS) && isPositive(forceFramePeriodS) && isPositive(maxForceSlewNPerS) &&
         isPositive(watchdogS) && isNonNegative(magnetLagS) && isFraction(maxDriveLevel) &&
         isPositive(heatTimeConstantS) && isFraction(heatRatedDuty);
}

}  // namespace kf
