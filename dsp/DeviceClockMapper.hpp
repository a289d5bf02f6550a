// DeviceClockMapper: puts device timestamps of mouse reports onto audio time.
//
// A report reaches the audio side at arrival = device + offset + delay, with delay >= 0 (the
// rest of the current block, the queue). So offset (audio - device) is the lower envelope of
// d = arrival - device. Two stages:
//  1. The floor: the minimum over a sliding horizon of d_i + leak * (t - t_i), leak a little
//     above the largest drift, so it can rise as fast as the true offset while any lower
//     observation pulls it down at once. (Minimum of d_i - leak * t_i: a monotonic deque in
//     fixed storage.)
//  2. The mapping: a second-order loop (offset and drift rate, critically damped, ~3 s) that
//     follows the floor. Why: 125 Hz reports against 1.33 ms blocks see the same block phase
//     again and again, so under drift the floor is a staircase with steps of a whole block
//     every few seconds; the loop turns that into a smooth line with the drift's slope
//     (clamped to +-maxDriftPpm) instead of 1.3 ms jumps of report times.
// Mapped times never go backward while device times go forward: a drop is spread out so the
// mapped time still advances by at least minAdvanceRatio of the device time. A floor more
// than snapS away from the mapping is taken at once (start-up, a stall). In lockstep (NRT:
// arrival == device) the offset is exactly 0 and the mapping exact. Device time going
// backward (the device restarted) or d far below the estimate (the device clock jumped
// forward) resets the mapper. Nothing here allocates.
#pragma once

#include <array>
#include <cstdint>

namespace kf {

class DeviceClockMapper {
 public:
  struct Config {
    double horizonS = 2.0;         // how long one low observation holds the floor down
    double maxDriftPpm = 200.0;    // the floor may rise 25% faster; drift clamped to this
    double loopTimeS = 3.0;        // 1 / natural frequency of the smoothing loop
    double snapS = 0.004;          // floor this far from the mapping: take it at once
    double resetJumpS = 0.1;       // d this far below the estimate: a new device clock
    double minAdvanceRatio = 0.5;  // mapped time advances >= this * device time advance
    double extraLatencyS = 0.0;    // added to every mapped time (headroom for jitter)
  };

  DeviceClockMapper();
  explicit DeviceClockMapper(const Config& config);

  // Observes one report (in order of arrival) and returns its audio time.
  double map(double deviceTimeS, double arrivalAudioTimeS);
  // Maps without observing (the current estimate); deviceTimeS itself before any report.
  double mapOnly(double deviceTimeS) const;

  void reset();
  bool hasEstimate() const { return hasLast_; }
  // The offset (audio - device) applied to the last report, without extraLatencyS.
  double offsetS() const { return appliedOffsetS_; }
  // The floor (lower envelope) at the last report, before smoothing.
  double floorOffsetS() const { return floorOffsetS_; }
  int64_t resetCount() const { return resetCount_; }
  // The loop's estimate of the rate of change of (audio - device).
  double driftPpm() const { return driftPerS_ * 1e6; }
  const Config& config() const { return config_; }

 private:
  static constexpr int kCapacity = 512;  // 4 s of 125 Hz reports, 0.5 s at 1 kHz
  struct Entry {
    double deviceTimeS;
    double keyS;  // d - leak * (device - reference): its minimum gives the floor
  };

  void restart(double deviceTimeS);
  double floorAt(double deviceTimeS) const;  // needs count_ > 0

  Config config_;
  double leakPerS_;
  std::array<Entry, kCapacity> entries_{};
  int head_ = 0;   // oldest
  int count_ = 0;  // keys ascending from head_
  double referenceS_ = 0.0;

  bool hasLast_ = false;
  double lastDeviceS_ = 0.0;
  double loopOffsetS_ = 0.0;  // the smoothing loop's state
  double driftPerS_ = 0.0;
  double appliedOffsetS_ = 0.0;  // after spreading a drop
  double floorOffsetS_ = 0.0;
  int64_t resetCount_ = 0;
};

}  // namespace kf
