#include "core/spec/DeviceSpec.hpp"

#include <cmath>

#include "core/spec/SettingBounds.hpp"

namespace kf {

namespace {

struct Field {
  std::string_view name;
  double DeviceSpec::*field;
};
constexpr Field kFields[] = {
    {"countMm", &DeviceSpec::countMm},
    {"updateRateHz", &DeviceSpec::updateRateHz},
    {"minForceN", &DeviceSpec::minForceN},
    {"maxForceN", &DeviceSpec::maxForceN},
    {"audioLatencyS", &DeviceSpec::audioLatencyS},
    {"tactileLatencyS", &DeviceSpec::tactileLatencyS},
    {"forceFramePeriodS", &DeviceSpec::forceFramePeriodS},
    {"maxForceSlewNPerS", &DeviceSpec::maxForceSlewNPerS},
    {"watchdogS", &DeviceSpec::watchdogS},
    {"magnetLagS", &DeviceSpec::magnetLagS},
    {"maxDriveLevel", &DeviceSpec::maxDriveLevel},
    {"heatTimeConstantS", &DeviceSpec::heatTimeConstantS},
    {"heatRatedDuty", &DeviceSpec::heatRatedDuty},
    {"countMmY", &DeviceSpec::countMmY},
    {"swapXY", &DeviceSpec::swapXY},
    {"signX", &DeviceSpec::signX},
    {"signY", &DeviceSpec::signY},
};

bool fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

}  // namespace

bool DeviceSpec::applyOverride(std::string_view key, double value, std::string* error) {
  const bool isCounts = key == "maxCountsPerReport";
  double DeviceSpec::*target = nullptr;
  for (const Field& entry : kFields)
    if (entry.name == key) target = entry.field;
  if (target == nullptr && !isCounts) return fail(error, "unknown device setting '" + std::string(key) + "'");
  if (std::string message = checkSetting(key, value); !message.empty()) return fail(error, message);
  if (isCounts)
    maxCountsPerReport = static_cast<int>(value);
  else
    this->*target = value;
  return true;
}

bool DeviceSpec::isValid(std::string* error) const {
  for (const Field& entry : kFields)
    if (std::string message = checkSetting(entry.name, this->*entry.field); !message.empty())
      return fail(error, message);
  if (std::string message = checkSetting("maxCountsPerReport", maxCountsPerReport); !message.empty())
    return fail(error, message);
  if (minForceN > maxForceN) return fail(error, "minForceN is above maxForceN");
  if (signX == 0.0 || signY == 0.0) return fail(error, "signX and signY are 1 or -1");
  if (countMmY != 0.0 && countMmY < 1e-4) return fail(error, "countMmY is 0 (as countMm) or 0.0001..10 mm");
  // The watchdog must not trip between two frames that arrive on time.
  if (watchdogS < 2.0 * forceFramePeriodS) return fail(error, "watchdogS is shorter than two force frames");
  return true;
}

}  // namespace kf
