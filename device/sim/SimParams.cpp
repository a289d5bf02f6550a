#include "sim/SimParams.hpp"

#include <algorithm>
#include <iterator>
#include <limits>

#include "core/spec/SettingBounds.hpp"

namespace kf {

namespace {

struct Field {
  std::string_view name;
  double SimParams::*field;
};
constexpr Field kFields[] = {
    {"handStiffnessNPerM", &SimParams::handStiffnessNPerM},
    {"handDampingNSPerM", &SimParams::handDampingNSPerM},
    {"handMaxForceN", &SimParams::handMaxForceN},
    {"puckMassKg", &SimParams::puckMassKg},
    {"stepS", &SimParams::stepS},
    {"handHeld", &SimParams::handHeld},
    {"reportJitterS", &SimParams::reportJitterS},
    {"dropProbability", &SimParams::dropProbability},
    {"clockDriftPpm", &SimParams::clockDriftPpm},
};

}  // namespace

bool SimParams::applyOverride(std::string_view key, double value, std::string* error) {
  auto fail = [error](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  const bool known =
      key == "seed" || key == "liftStartS" || key == "liftEndS" ||
      std::any_of(std::begin(kFields), std::end(kFields), [key](const Field& f) { return f.name == key; });
  if (!known) return fail("unknown simulation setting '" + std::string(key) + "'");
  if (std::string message = checkSetting(key, value); !message.empty()) return fail(message);
  for (const Field& entry : kFields) {
    if (entry.name == key) {
      this->*entry.field = value;
      return true;
    }
  }
  if (key == "seed") {
    seed = static_cast<uint64_t>(value);
  } else if (key == "liftStartS") {
    liftIntervalsS.emplace_back(value, std::numeric_limits<double>::infinity());
  } else {  // liftEndS
    if (liftIntervalsS.empty() || value < liftIntervalsS.back().first)
      return fail("liftEndS must follow a liftStartS and not come before it");
    liftIntervalsS.back().second = value;
  }
  return true;
}

bool SimParams::isValid(std::string* error) const {
  std::string message;
  for (const Field& entry : kFields)
    if (message.empty()) message = checkSetting(entry.name, this->*entry.field);
  if (message.empty()) message = checkSetting("seed", static_cast<double>(seed));
  for (const auto& [startS, endS] : liftIntervalsS)
    if (message.empty() && !(startS >= 0.0 && endS >= startS)) message = "lift interval ends before it starts";
  if (error) *error = message;
  return message.empty();
}

}  // namespace kf
