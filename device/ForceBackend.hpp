// ForceBackend: the magnet side of a device (simulated magnet, counting sink, USB driver).
// It receives forces that ForceSafety has already made safe.
#pragma once

namespace kf {

class ForceBackend {
 public:
  virtual ~ForceBackend() = default;
  // From device time `timeS` on, the magnet should produce `forceN` of kinetic friction.
  virtual void commandForce(double timeS, float forceN) = 0;
  // Magnet off now (minimum friction): on close, watchdog trips, errors.
  virtual void driveOff() = 0;
};

}  // namespace kf
