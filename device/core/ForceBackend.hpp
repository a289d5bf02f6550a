// ForceBackend: the magnet side of a device (simulated magnet, counting sink, USB driver).
// It receives forces that ForceSafety has already made safe.
#pragma once

#include <atomic>
#include <cstdint>

namespace kf {

class ForceBackend {
 public:
  virtual ~ForceBackend() = default;
  // From device time `timeS` on, the magnet should produce `forceN` of kinetic friction.
  virtual void commandForce(double timeS, float forceN) = 0;
  // The same command with its drive level (0..1 of full-scale current) after calibration and
  // the drive limits: hardware uses the drive, models the force.
  virtual void commandDrive(double timeS, float forceN, float /*driveLevel*/) { commandForce(timeS, forceN); }
  // Magnet off now (minimum friction): on close, watchdog trips, errors.
  virtual void driveOff() = 0;
  // Magnet off from a signal handler (SIGTERM, a crash): async-signal-safe only — no lock,
  // no allocation, no stdio. The default calls driveOff(), which suits backends whose
  // driveOff() only stores values; a backend that talks to hardware through a library must
  // override it (e.g. a write(2) of a prepared off command on its open descriptor).
  virtual void driveOffFromSignal() noexcept { driveOff(); }
  // True once after the magnet was switched on from off by the backend's own request (a board
  // armed): the device then restarts its slew limiter from minForceN before the next frame, so
  // the force rises from the minimum at the slew limit instead of jumping to the last request.
  virtual bool takeRestartFromOff() { return false; }
};

// The force side of a device without a magnet (replay, a mouse alone): counts what it is told.
// Readable from any thread.
class CountingForceSink : public ForceBackend {
 public:
  void commandForce(double timeS, float forceN) override {
    lastForceN_.store(forceN, std::memory_order_relaxed);
    lastTimeS_.store(timeS, std::memory_order_relaxed);
    commands_.fetch_add(1, std::memory_order_relaxed);
  }
  void driveOff() override { driveOffs_.fetch_add(1, std::memory_order_relaxed); }

  uint64_t commands() const { return commands_.load(std::memory_order_relaxed); }
  uint64_t driveOffs() const { return driveOffs_.load(std::memory_order_relaxed); }
  float lastForceN() const { return lastForceN_.load(std::memory_order_relaxed); }
  double lastTimeS() const { return lastTimeS_.load(std::memory_order_relaxed); }

 private:
  std::atomic<uint64_t> commands_{0};
  std::atomic<uint64_t> driveOffs_{0};
  std::atomic<float> lastForceN_{0.0f};
  std::atomic<double> lastTimeS_{0.0};
};

}  // namespace kf
