// MouseProfile: what one mouse on one surface needs to report millimetres — the count size of
// each axis, measured from a stroke of known length, or the maker's CPI as a starting value,
// and how the mouse sits in the puck (swap and signs of its axes) — kept per device in a small
// "key = value" text file (docs/mouse-profile-format.md):
//
//   # kf-mouse-profile 1
//   name = Genius Gila Gaming Mouse
//   vendorId = 0458
//   productId = 0138
//   serial =
//   surface = steel sheet, matte paint
//   cpi = 1200
//   countMmX = 0.02108
//   countMmY = 0.02131
//   swapXY = 0
//   signX = 1
//   signY = -1
//   updateRateHz = 500
//
// Unknown keys are kept out of the way (ignored), so newer files still load.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "core/spec/DeviceSpec.hpp"

namespace kf {

// The count size (mm) of an axis on which the puck moved strokeMm along a ruler while the
// mouse summed `counts` (either sign). NaN when counts is 0 or strokeMm not positive/finite.
double countMmFromStroke(int64_t counts, double strokeMm);
// The maker's counts per inch as a count size (mm): a starting value before a stroke.
double countMmFromCpi(double cpi);

struct MouseProfile {
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  std::string name, serial, surface;
  uint16_t vendorId = 0, productId = 0;
  double cpi = kUnset;
  // Along the surface's x and y (after the swap): what a stroke along each measures.
  double countMmX = kUnset, countMmY = kUnset;
  double updateRateHz = kUnset;
  // The surface's axes from the mouse's: swapXY 1 exchanges x and y, then signX, signY -1
  // reverse one (DeviceSpec::countsToMm).
  bool swapXY = false;
  int signX = 1, signY = 1;

  // countMmX if measured, else from cpi; NaN if neither.
  double countMm() const;
  // Sets the spec's countMm, countMmY (and updateRateHz) and its axes from what the profile
  // has; false (the axes still set) when it has no count size.
  bool applyTo(DeviceSpec& spec) const;
};

bool writeMouseProfile(const std::string& path, const MouseProfile& profile, std::string& error);
// False with a message naming the line on a malformed line or a value out of range.
bool readMouseProfile(const std::string& path, MouseProfile& out, std::string& error);

}  // namespace kf
