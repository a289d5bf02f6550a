// libFuzzer target: the kf-calibration reader (docs/calibration-format.md). Whatever it accepts
// must be a table the force path can use: inverting any force gives a finite drive level in
// 0..1 and the forward map stays within the table's forces.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/force/CalibrationTable.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  kf::CalibrationTable table = kf::CalibrationTable::linear(0.14, 1.4);
  std::string error;
  if (!kf::CalibrationTable::parse(text, table, error)) return 0;
  for (double forceN : {-1e300, -1.0, 0.0, 0.14, 0.5, 1.4, 10.0, 1e300}) {
    const double drive = table.driveForForce(forceN);
    if (!std::isfinite(drive) || drive < 0.0 || drive > 1.0) __builtin_trap();
    if (!std::isfinite(table.forceForDrive(drive))) __builtin_trap();
  }
  return 0;
}
