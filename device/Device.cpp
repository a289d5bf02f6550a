#include "Device.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace kf {

Device::Device(const DeviceSpec& spec, std::shared_ptr<MouseBackend> mouse, std::shared_ptr<ForceBackend> force,
               bool lockstep, DeviceOptions options)
    : spec_(spec),
      lockstep_(lockstep),
      options_(options),
      mouse_(std::move(mouse)),
      force_(std::move(force)),
      reportQueue_(options.reportQueueCapacity),
      frameQueue_(options.frameQueueCapacity),
      safety_(spec),
      startTime_(std::chrono::steady_clock::now()) {
  telemetry_.setCommandedForce(static_cast<float>(spec.minForceN));
}

Device::~Device() { close(); }

void Device::start() {
  if (lockstep_ || thread_.joinable() || isClosed()) return;
  stopRequested_.store(false);
  startTime_ = std::chrono::steady_clock::now();
  thread_ = std::thread([this] { threadMain(); });
}

void Device::threadMain() {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point openTime = startTime_;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.pumpPeriodS));
  Clock::time_point next = openTime;
  while (!stopRequested_.load(std::memory_order_acquire)) {
    next += period;
    std::this_thread::sleep_until(next);
    const Clock::time_point now = Clock::now();
    // After a long stall, do not try to catch up with a burst of pumps.
    if (now - next > 10 * period) next = now;
    const double nowS = std::chrono::duration<double>(now - openTime).count();
    if (lastPumpS_ >= 0.0) telemetry_.pumpPeriod.record(nowS - lastPumpS_);
    std::lock_guard<std::mutex> lock(stateMutex_);
    pumpLocked(nowS);
  }
}

void Device::pump(double nowS) {
  if (!lockstep_ || isClosed()) return;
  // try_lock: the audio thread never waits; a skipped round is caught up by the next one.
  std::unique_lock<std::mutex> lock(stateMutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  pumpLocked(nowS - lockstepOriginS_);
}

void Device::pumpLocked(double nowS) {
  if (!(nowS > lastPumpS_)) return;

  ForceFrame frame;
  while (frameQueue_.pop(frame)) {
    const float commandedN = safety_.applyFrame(frame, nowS);
    if (!lockstep_) telemetry_.forceLatency.record(nowS - frame.endedHostS);
    // Lockstep: device and audio time are one clock, so the frame is stamped with its own time
    // (never before an earlier command, never in the future); a backend that has already
    // passed that time (the sim, one block on) applies it at once, as a realtime device would.
    // Realtime: now.
    double commandS = nowS;
    if (lockstep_ && std::isfinite(frame.timeS))
      commandS = std::clamp(frame.timeS, std::min(lastCommandS_, nowS), nowS);
    lastCommandS_ = commandS;
    force_->commandForce(commandS, commandedN);
    telemetry_.countFrame(commandedN);
    recorder_.writeFrame(nowS, frame, commandedN);
  }
  if (safety_.checkWatchdog(nowS)) {
    force_->driveOff();
    telemetry_.countWatchdogTrip();
    telemetry_.setCommandedForce(safety_.commandedForceN());
    recorder_.writeOff(nowS);
  }

  int polled = 0;
  do {
    polled = mouse_->pollReports(nowS, pollBuffer_, kPollBatch);
    for (int i = 0; i < polled; ++i) {
      pollBuffer_[i].hostTimeS = nowS;
      xCounts_ += pollBuffer_[i].dxCounts;
      yCounts_ += pollBuffer_[i].dyCounts;
      pollBuffer_[i].xCounts = xCounts_;
      pollBuffer_[i].yCounts = yCounts_;
      telemetry_.countReport(pollBuffer_[i].deviceTimeS);
      recorder_.writeReport(nowS, pollBuffer_[i]);
      reportQueue_.push(pollBuffer_[i]);  // a full queue counts the overflow
    }
  } while (polled == kPollBatch);

  recorder_.flush();
  lastPumpS_ = nowS;
  lastPumpAtomicS_.store(nowS, std::memory_order_relaxed);
  telemetry_.countPump();
}

void Device::close() {
  if (closed_.exchange(true, std::memory_order_acq_rel)) return;
  stopRequested_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(stateMutex_);
  force_->driveOff();
  safety_.resetToOff();
  telemetry_.setCommandedForce(safety_.commandedForceN());
  recorder_.writeOff(std::max(lastPumpS_, 0.0));
  recorder_.close();
}

int Device::popReports(MouseReport* out, int capacity) {
  int popped = 0;
  while (popped < capacity && reportQueue_.pop(out[popped])) ++popped;
  if (!lockstep_ && popped > 0) {
    const double now = nowS();
    for (int i = 0; i < popped; ++i) telemetry_.reportLatency.record(now - out[i].hostTimeS);
  }
  return popped;
}

double Device::nowS() const {
  if (lockstep_) return lastPumpAtomicS_.load(std::memory_order_relaxed);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - startTime_).count();
}

bool Device::pushForceFrame(const ForceFrame& frame) { return frameQueue_.push(frame); }

TelemetrySnapshot Device::telemetry() const {
  TelemetrySnapshot snapshot = telemetry_.snapshot();
  snapshot.reportQueueOverflows = reportQueue_.overflows();
  snapshot.frameQueueOverflows = frameQueue_.overflows();
  return snapshot;
}

bool Device::startRecording(const std::string& path, std::string& error) {
  std::lock_guard<std::mutex> lock(stateMutex_);
  if (isClosed()) {
    error = "the device is closed";
    return false;
  }
  return recorder_.open(path, spec_, error);
}

void Device::stopRecording() {
  std::lock_guard<std::mutex> lock(stateMutex_);
  recorder_.close();
}

}  // namespace kf
