// SettingBounds: the one table of what every device setting and file field may hold — what a
// real device and scene can mean, and nothing that makes a loop, an allocation or a wait
// unbounded or an output non-finite. DeviceSpec and SimParams overrides, session-file
// headers, hand scripts and the checks of a whole spec all ask here. Defaults live with
// their structs; only the bounds live here.
#pragma once

#include <string>
#include <string_view>

namespace kf {

struct SettingBounds {
  std::string_view name;  // the member or file field name
  double min;             // inclusive
  double max;             // inclusive
  bool integer;           // whole numbers only
  std::string_view unit;  // for messages
};

// The bounds of a named setting, or null for a name the table does not know.
const SettingBounds* findSettingBounds(std::string_view name);

// True when `value` is finite, within the bounds (and whole if it must be).
bool isWithinBounds(const SettingBounds& bounds, double value);

// A value sent as a 32-bit float (as sclang sends numbers) that is a bound at that precision
// becomes the bound: "countMm 0.0001" from sclang arrives as 1.0000000e-4f, below the double
// 1e-4, and a bound the help writes must be accepted as written. Other values are unchanged.
double snapToBounds(std::string_view name, double value);

// Empty when the value is allowed; otherwise a message naming field, value and range, e.g.
// "countMm = 1e+300 is out of range 0.0001..10 mm". Unknown names give "unknown setting".
std::string checkSetting(std::string_view name, double value);

}  // namespace kf
