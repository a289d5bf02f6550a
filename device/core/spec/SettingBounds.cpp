#include "core/spec/SettingBounds.hpp"

#include <cmath>
#include <cstdio>

namespace kf {

namespace {

// Why each bound: rates and periods keep the per-block and per-pump work to a few thousand
// iterations (the audio thread frames forces, the device thread steps the simulation); sizes
// and forces keep every product (counts x countMm x rate, force / mass x step^2) finite.
constexpr SettingBounds kBounds[] = {
    // DeviceSpec
    {"countMm", 1e-4, 10.0, false, "mm"},                  // 254000 down to 2.5 counts per inch
    {"updateRateHz", 1.0, 8000.0, false, "Hz"},            // USB full/high-speed mice: 125..8000 Hz
    {"maxCountsPerReport", 1.0, 32767.0, true, "counts"},  // up to int16 reports
    {"minForceN", 0.0, 50.0, false, "N"},
    {"maxForceN", 0.0, 50.0, false, "N"},
    {"audioLatencyS", 0.0, 1.0, false, "s"},
    {"tactileLatencyS", 0.0, 1.0, false, "s"},
    {"forceFramePeriodS", 1e-4, 0.1, false, "s"},  // 10 kHz .. 10 Hz force frames
    {"maxForceSlewNPerS", 0.01, 1e6, false, "N/s"},
    {"watchdogS", 0.002, 10.0, false, "s"},
    {"magnetLagS", 0.0, 1.0, false, "s"},
    {"maxDriveLevel", 1e-3, 1.0, false, "of full-scale drive"},
    {"heatTimeConstantS", 0.01, 1e5, false, "s"},
    {"heatRatedDuty", 1e-3, 1.0, false, "of full-scale drive squared"},
    {"countMmY", 0.0, 10.0, false, "mm"},  // 0: as countMm; else as countMm's bounds (DeviceSpec::isValid)
    {"swapXY", 0.0, 1.0, true, ""},
    {"signX", -1.0, 1.0, true, ""},  // -1 or 1 (DeviceSpec::isValid refuses 0)
    {"signY", -1.0, 1.0, true, ""},
    // DeviceOptions: the device's threads, -1 auto, 0 normal scheduling, 1..98 SCHED_FIFO
    {"threadPriority", -1.0, 98.0, true, ""},
    // ReplayOptions
    {"startS", 0.0, 1e6, false, "s"},
    {"rate", 0.01, 100.0, false, ""},  // a replay at 1/100 .. 100 times the recorded speed
    {"skipIdle", 0.0, 1.0, true, ""},
    {"loop", 0.0, 1.0, true, ""},
    // SimParams
    {"handStiffnessNPerM", 0.0, 1e4, false, "N/m"},
    {"handDampingNSPerM", 0.0, 1e3, false, "N s/m"},
    {"handMaxForceN", 0.0, 100.0, false, "N"},
    {"puckMassKg", 1e-3, 10.0, false, "kg"},
    {"stepS", 1e-6, 0.01, false, "s"},  // at most 10^6 steps per simulated second
    {"handHeld", 0.0, 1.0, true, ""},
    {"reportJitterS", 0.0, 0.1, false, "s"},
    {"dropProbability", 0.0, 1.0, false, ""},
    {"clockDriftPpm", -1e5, 1e5, false, "ppm"},
    {"seed", 0.0, 9007199254740992.0, true, ""},  // 2^53: every double integer below is exact
    {"liftStartS", 0.0, 1e6, false, "s"},
    {"liftEndS", 0.0, 1e6, false, "s"},
    // Hand scripts (kfOpenSim values)
    {"handTimeS", -1e6, 1e6, false, "s"},
    {"handPositionMm", -1e6, 1e6, false, "mm"},
    {"handSpeedMmPerS", -1e5, 1e5, false, "mm/s"},
    {"handDurationS", 0.0, 1e6, false, "s"},
    {"handForceN", -100.0, 100.0, false, "N"},
};

}  // namespace

const SettingBounds* findSettingBounds(std::string_view name) {
  for (const SettingBounds& bounds : kBounds)
    if (bounds.name == name) return &bounds;
  return nullptr;
}

bool isWithinBounds(const SettingBounds& bounds, double value) {
  return std::isfinite(value) && value >= bounds.min && value <= bounds.max &&
         (!bounds.integer || value == std::floor(value));
}

double snapToBounds(std::string_view name, double value) {
  const SettingBounds* bounds = findSettingBounds(name);
  if (bounds == nullptr || !std::isfinite(value)) return value;
  const float asSent = static_cast<float>(value);
  if (asSent == static_cast<float>(bounds->min)) return bounds->min;
  if (asSent == static_cast<float>(bounds->max)) return bounds->max;
  return value;
}

std::string checkSetting(std::string_view name, double value) {
  const SettingBounds* bounds = findSettingBounds(name);
  char text[256];
  if (bounds == nullptr) {
    std::snprintf(text, sizeof text, "unknown setting '%.*s'", static_cast<int>(name.size()), name.data());
    return text;
  }
  if (isWithinBounds(*bounds, value)) return {};
  std::snprintf(text, sizeof text, "%.*s = %g is out of range %g..%g%s%.*s%s", static_cast<int>(name.size()),
                name.data(), std::isnan(value) ? std::fabs(value) : value, bounds->min, bounds->max,
                bounds->unit.empty() ? "" : " ", static_cast<int>(bounds->unit.size()), bounds->unit.data(),
                bounds->integer ? " (whole numbers)" : "");
  return text;
}

}  // namespace kf
