#include "sim/SimDevice.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kf {

SimDevice::SimDevice(const DeviceSpec& spec, const SimParams& params, const HandScript& hand)
    : spec_(spec),
      params_(params),
      hand_(hand),
      exploring_(hand.kind == HandScript::Kind::kExplore),
      explorer_(hand.explore),
      puck_(params.puckMassKg),
      magnet_(spec.magnetLagS, params.stepS, spec.minForceN),
      sensor_(spec, params, 0.0),
      buffer_(kReportBufferCapacity),
      handHeld_(params.handHeld != 0.0) {}

SimDevice::Push SimDevice::handPush(double timeS) const {
  if (hand_.isIdle()) return {};
  if (hand_.isForce()) return {hand_.constantForceN(), 0.0};
  // A spring-damper between hand and puck on each axis, the push limited in magnitude to what a
  // fingertip pushes (along x alone: clamped to +-handMaxForceN, as before there was a y).
  const HandTarget target = hand_.at(handTimeS(timeS));
  auto spring = [&](double targetMm, double puckMm, double targetMmPerS, double puckMmPerS) {
    // Metres first, then the gains: the 1D model's rounding, so that x alone stays bit for bit.
    return params_.handStiffnessNPerM * ((targetMm - puckMm) * 1e-3) +
           params_.handDampingNSPerM * ((targetMmPerS - puckMmPerS) * 1e-3);
  };
  const double x = spring(target.positionMm, positionMm(), target.speedMmPerS, speedMmPerS());
  const double y = spring(target.yMm, positionYMm(), target.speedYMmPerS, speedYMmPerS());
  if (y == 0.0) return {std::clamp(x, -params_.handMaxForceN, params_.handMaxForceN), 0.0};
  const double magnitude = std::hypot(x, y);
  const double scale = magnitude > params_.handMaxForceN ? params_.handMaxForceN / magnitude : 1.0;
  return {x * scale, y * scale};
}

void SimDevice::step() {
  const double startS = timeS();
  const double startMm = positionMm(), startYMm = positionYMm();
  if (handHeld_ && releaseRequested_.load(std::memory_order_acquire)) {
    handHeld_ = false;
    handStartS_ = startS;
  }
  Push push;  // a held hand pushes nothing
  if (!handHeld_)
    push = exploring_ ? Push{explorer_.push(handTimeS(startS), params_.stepS, startMm, speedMmPerS()), 0.0}
                      : handPush(startS);
  handForceN_ = push.xN;
  handForceYN_ = push.yN;
  puck_.step(params_.stepS, push.xN, push.yN, magnet_.forceN());
  magnet_.step();
  ++stepIndex_;
  const double endS = timeS();
  const double endMm = positionMm(), endYMm = positionYMm();
  while (sensor_.nextReportTimeS() <= endS) {
    // Position at the report instant, linear within the step.
    const double fraction = std::clamp((sensor_.nextReportTimeS() - startS) / params_.stepS, 0.0, 1.0);
    MouseReport report;
    if (sensor_.takeReport(startMm + (endMm - startMm) * fraction, startYMm + (endYMm - startYMm) * fraction, report))
      storeReport(report);
  }
}

void SimDevice::advanceTo(double timeS) {
  // The small epsilon keeps times that are whole steps from losing one to rounding.
  const auto targetStep = static_cast<int64_t>(std::floor(timeS / params_.stepS + 1e-6));
  while (stepIndex_ < targetStep) step();
}

void SimDevice::storeReport(const MouseReport& report) {
  if (bufferCount_ == kReportBufferCapacity) {
    // Nobody polls: keep the newest.
    bufferHead_ = (bufferHead_ + 1) % kReportBufferCapacity;
    --bufferCount_;
    ++bufferOverflows_;
  }
  buffer_[(bufferHead_ + bufferCount_) % kReportBufferCapacity] = report;
  ++bufferCount_;
}

int SimDevice::pollReports(double untilTimeS, MouseReport* out, int capacity) {
  if (failNextPoll_.exchange(false, std::memory_order_acq_rel))
    throw std::runtime_error("the simulated device failed (kfSimFail)");
  advanceTo(untilTimeS);
  int written = 0;
  while (written < capacity && bufferCount_ > 0) {
    out[written++] = buffer_[bufferHead_];
    bufferHead_ = (bufferHead_ + 1) % kReportBufferCapacity;
    --bufferCount_;
  }
  return written;
}

void SimDevice::commandForce(double timeS, float forceN) {
  advanceTo(timeS);
  // Where in the step it falls (frames at 8 kHz are 1.25 steps apart); a nanosecond or less is
  // the step's start, as float rounding puts 1 kHz frames there.
  const double intoStepS = timeS - this->timeS();
  magnet_.command(forceN, intoStepS > 1e-9 ? intoStepS : 0.0);
}

void SimDevice::driveOff() { magnet_.command(spec_.minForceN); }

}  // namespace kf
