#include "DeviceClockMapper.hpp"

#include <algorithm>
#include <cmath>

namespace kf {

DeviceClockMapper::DeviceClockMapper() : DeviceClockMapper(Config{}) {}

DeviceClockMapper::DeviceClockMapper(const Config& config) : config_(config) {
  config_.minAdvanceRatio = std::clamp(config_.minAdvanceRatio, 0.0, 1.0);
  config_.maxDriftPpm = std::max(0.0, config_.maxDriftPpm);
  config_.loopTimeS = std::max(0.05, config_.loopTimeS);
  leakPerS_ = 1.25e-6 * config_.maxDriftPpm;
}

void DeviceClockMapper::reset() {
  restart(0.0);
  appliedOffsetS_ = 0.0;
  floorOffsetS_ = 0.0;
}

void DeviceClockMapper::restart(double deviceTimeS) {
  head_ = 0;
  count_ = 0;
  referenceS_ = deviceTimeS;
  hasLast_ = false;
  loopOffsetS_ = 0.0;
  driftPerS_ = 0.0;
}

double DeviceClockMapper::floorAt(double deviceTimeS) const {
  // min_i (d_i + leak * (t - t_i)) = leak * (t - ref) + min_i key_i; the head is the minimum.
  return leakPerS_ * (deviceTimeS - referenceS_) + entries_[head_].keyS;
}

double DeviceClockMapper::map(double deviceTimeS, double arrivalAudioTimeS) {
  const double delayS = arrivalAudioTimeS - deviceTimeS;
  if (hasLast_ && deviceTimeS < lastDeviceS_) {
    ++resetCount_;  // the device clock went back: a restarted device
    restart(deviceTimeS);
  } else if (hasLast_ && delayS < floorAt(deviceTimeS) - config_.resetJumpS) {
    ++resetCount_;  // earlier than any delay allows: the device clock jumped forward
    restart(deviceTimeS);
  }
  if (!hasLast_) referenceS_ = deviceTimeS;

  // 1. The floor over the horizon.
  const double key = delayS - leakPerS_ * (deviceTimeS - referenceS_);
  while (count_ > 0 && entries_[head_].deviceTimeS < deviceTimeS - config_.horizonS) {
    head_ = (head_ + 1) % kCapacity;
    --count_;
  }
  while (count_ > 0 && entries_[(head_ + count_ - 1) % kCapacity].keyS >= key) --count_;
  if (count_ == kCapacity) {  // full of ascending keys: drop the oldest (a shorter horizon)
    head_ = (head_ + 1) % kCapacity;
    --count_;
  }
  entries_[(head_ + count_) % kCapacity] = Entry{deviceTimeS, key};
  ++count_;
  floorOffsetS_ = floorAt(deviceTimeS);

  // 2. The loop: o' = r + 2 w e, r' = w^2 e (critically damped, w = 1 / loopTimeS).
  const double advanceS = hasLast_ ? deviceTimeS - lastDeviceS_ : 0.0;
  if (!hasLast_) {
    loopOffsetS_ = floorOffsetS_;
    driftPerS_ = 0.0;
  } else {
    const double stepS = std::min(advanceS, 0.25 * config_.loopTimeS);  // keeps it stable
    const double predictedS = loopOffsetS_ + driftPerS_ * advanceS;
    const double errorS = floorOffsetS_ - predictedS;
    if (std::fabs(errorS) > config_.snapS) {
      loopOffsetS_ = floorOffsetS_;
    } else {
      const double w = 1.0 / config_.loopTimeS;
      loopOffsetS_ = predictedS + 2.0 * w * stepS * errorS;
      const double maxPerS = 1e-6 * config_.maxDriftPpm;
      driftPerS_ = std::clamp(driftPerS_ + w * w * stepS * errorS, -maxPerS, maxPerS);
    }
  }

  if (!hasLast_) {
    appliedOffsetS_ = loopOffsetS_;
  } else {
    // A drop is taken in steps small enough that mapped time keeps advancing.
    const double lowestS = appliedOffsetS_ - (1.0 - config_.minAdvanceRatio) * advanceS;
    appliedOffsetS_ = std::max(loopOffsetS_, lowestS);
  }
  hasLast_ = true;
  lastDeviceS_ = deviceTimeS;
  return deviceTimeS + appliedOffsetS_ + config_.extraLatencyS;
}

double DeviceClockMapper::mapOnly(double deviceTimeS) const {
  return deviceTimeS + (hasLast_ ? appliedOffsetS_ : 0.0) + config_.extraLatencyS;
}

}  // namespace kf
