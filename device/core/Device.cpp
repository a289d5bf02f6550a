#include "core/Device.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <string>

#include "core/threads/DeviceMessages.hpp"

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
      pending_(std::max<size_t>(options.frameQueueCapacity, 1)),
      releaseLatencyS_(
          std::min(spec.forceFramePeriodS + options.audioPeriodS + options.pumpPeriodS, options.maxForceLatencyS)),
      startTime_(std::chrono::steady_clock::now()) {
  telemetry_.setCommandedForce(static_cast<float>(spec.minForceN));
  telemetry_.setReleaseLatency(releaseLatencyS_);
}

Device::~Device() { close(); }

void Device::start() {
  if (lockstep_ || options_.externalPump || thread_.joinable() || isClosed()) return;
  stopRequested_.store(false);
  // Realtime: the device's own memory stays in RAM (ThreadScheduling's lockMemory).
  memoryLocked_ = options_.thread.priority != kNormalPriority && lockMemory(this, sizeof(Device)) &&
                  lockMemory(reportQueue_.storage(), reportQueue_.storageBytes()) &&
                  lockMemory(frameQueue_.storage(), frameQueue_.storageBytes()) &&
                  lockMemory(pending_.data(), pending_.size() * sizeof(PendingFrame));
  startTime_ = std::chrono::steady_clock::now();
  thread_ = std::thread([this] { threadMain(); });
}

void Device::threadMain() {
  ThreadScheduling scheduling = scheduleThisThread("device", options_.thread);
  scheduling.memoryLocked = scheduling.memoryLocked && memoryLocked_;  // its stack and its memory
  threadScheduling_.store(scheduling);
  using Clock = std::chrono::steady_clock;
  const Clock::time_point openTime = startTime_;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.pumpPeriodS));
  Clock::time_point next = openTime;
  while (!stopRequested_.load(std::memory_order_acquire)) {
    next += period;
    sleepUntil(next);
    const Clock::time_point now = Clock::now();
    const double scheduledS = std::chrono::duration<double>(next - openTime).count();
    // Woken a whole period or more late: the deadlines passed meanwhile are missed, not caught
    // up with a burst of pumps; the next one is the grid's next after now. This pump judges
    // the frames against the deadline it missed and releases the newest that came due, not a
    // burst of stale force (releaseFramesLocked).
    if (now - next >= period) {
      const auto missed = (now - next) / period;
      telemetry_.countMissedDeadlines(static_cast<uint64_t>(missed));
      next += missed * period;
    }
    const double nowS = std::chrono::duration<double>(now - openTime).count();
    if (lastPumpS_ >= 0.0) telemetry_.pumpPeriod.record(nowS - lastPumpS_);
    std::lock_guard<PiMutex> lock(stateMutex_);
    try {
      pumpLocked(nowS, scheduledS);
    } catch (const std::exception& e) {
      failThread(e.what());
      return;
    } catch (...) {
      failThread("unknown exception");
      return;
    }
  }
}

void Device::failThread(const char* what) noexcept {
  // A backend threw: nothing pumps this device any more, so its magnet goes off now.
  try {
    force_->driveOff();
    if (board_) board_->driveOff();
  } catch (...) {
    force_->driveOffFromSignal();
    if (ForceBackend* board = board_.get()) board->driveOffFromSignal();
  }
  safety_.resetToOff();
  telemetry_.setCommandedForce(safety_.commandedForceN());
  threadFailed_.store(true, std::memory_order_release);
  try {
    recorder_.writeOff(std::max(lastPumpS_, 0.0), OffCause::kFailure);
    recorder_.close();
    postDeviceMessage((std::string("device thread stopped (") + what + "); magnet off, reopen the device").c_str());
  } catch (...) {
  }
}

void Device::pump(double nowS, double scheduledS) {
  if (options_.externalPump && !lockstep_ && !isClosed()) {
    std::lock_guard<PiMutex> lock(stateMutex_);
    pumpLocked(nowS, scheduledS < 0.0 ? nowS : std::min(scheduledS, nowS));
    return;
  }
  if (!lockstep_ || isClosed()) return;
  // try_lock: the audio thread never waits; a skipped round is caught up by the next one.
  std::unique_lock<PiMutex> lock(stateMutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  pumpLocked(nowS - lockstepOriginS_, nowS - lockstepOriginS_);
}

void Device::applyFrameLocked(const ForceFrame& frame, double commandS, double nowS) {
  if (board_ && board_->takeRestartFromOff()) safety_.resetToOff();  // armed: up from the minimum
  const float commandedN = safety_.applyFrame(frame, nowS);
  if (!lockstep_) telemetry_.forceLatency.record(nowS - frame.endedHostS);
  force_->commandDrive(commandS, commandedN, safety_.driveLevel());
  if (board_) board_->commandDrive(commandS, commandedN, safety_.driveLevel());
  telemetry_.countFrame(commandedN);
  recorder_.writeFrame(nowS, frame, commandedN);
}

void Device::applyLockstepFrameLocked(const ForceFrame& frame, double nowS) {
  // Device and audio time are one clock, so the frame is stamped with its own time (never
  // before an earlier command, never in the future); a backend that has already passed that
  // time (the sim, pumped to the end of the block) applies it at once, as a realtime device
  // would.
  double commandS = nowS;
  if (std::isfinite(frame.timeS)) commandS = std::clamp(frame.timeS, std::min(lastCommandS_, nowS), nowS);
  lastCommandS_ = commandS;
  applyFrameLocked(frame, commandS, nowS);
}

void Device::takeFramesLocked(double nowS, double scheduledS) {
  const double periodS = spec_.forceFramePeriodS;
  ForceFrame frame;
  while (frameQueue_.pop(frame)) {
    double startS = std::isfinite(frame.endedHostS) ? frame.endedHostS - periodS : frame.timeS;
    if (!std::isfinite(startS)) startS = nowS;
    // A frame later than the latency allows raises it, so the frames after it keep their
    // spacing instead of going out in a burst (a long audio period). Lateness counts to when
    // the pump was due: a late pump's own delay is no reason to hold every later frame back.
    const double latenessS = scheduledS - startS;
    windowLatenessS_ = std::max(windowLatenessS_, latenessS);
    // The first frame replaces the estimate made before any was measured (DeviceOptions).
    if (!latencyMeasured_) releaseLatencyS_ = std::clamp(latenessS, spec_.forceFramePeriodS, options_.maxForceLatencyS);
    latencyMeasured_ = true;
    releaseLatencyS_ = std::max(releaseLatencyS_, std::min(latenessS, options_.maxForceLatencyS));
    if (pendingCount_ == pending_.size()) {
      // Full: the oldest goes out now rather than being lost.
      applyFrameLocked(pending_[pendingHead_].frame, nowS, nowS);
      telemetry_.countLateFrame();
      pendingHead_ = (pendingHead_ + 1) % pending_.size();
      --pendingCount_;
    }
    pending_[(pendingHead_ + pendingCount_) % pending_.size()] = PendingFrame{frame, startS};
    ++pendingCount_;
  }
}

void Device::settleLatencyLocked(double nowS) {
  if (nowS >= windowEndS_) {
    previousWindowLatenessS_ = windowLatenessS_;
    windowLatenessS_ = 0.0;
    windowEndS_ = nowS + kLatencyWindowS;
  }
  // No frame in the last 0.5 to 1 s: nothing measured, the latency holds (at open, what a frame
  // can need before any is measured).
  if (windowLatenessS_ == 0.0 && previousWindowLatenessS_ == 0.0) return;
  // Down to what the frames of the last 0.5 to 1 s needed, never below a frame period, by 5 % of the
  // time since the last pump: one stall must not hold the force latency up for the rest of the session.
  const double neededS = std::min(std::max({spec_.forceFramePeriodS, windowLatenessS_, previousWindowLatenessS_}),
                                  options_.maxForceLatencyS);
  const double stepS = lastPumpS_ < 0.0 ? 0.0 : kLatencyDecayRate * std::max(nowS - lastPumpS_, 0.0);
  if (releaseLatencyS_ > neededS) releaseLatencyS_ = std::max(neededS, releaseLatencyS_ - stepS);
}

int Device::releaseFramesLocked(double nowS, bool latePump) {
  const double periodS = spec_.forceFramePeriodS;
  // The pump nearest the due time releases a frame: due times on the pump grid would otherwise
  // split between two pumps at the slightest wake-up jitter.
  auto isDue = [&](const PendingFrame& pending) {
    return pending.startS + releaseLatencyS_ <= nowS + 0.5 * options_.pumpPeriodS;
  };
  int released = 0;
  while (pendingCount_ > 0 && isDue(pending_[pendingHead_])) {
    const PendingFrame& pending = pending_[pendingHead_];
    const double dueS = pending.startS + releaseLatencyS_;
    const size_t after = (pendingHead_ + 1) % pending_.size();
    const bool newerDue = pendingCount_ > 1 && isDue(pending_[after]);
    pendingHead_ = after;
    --pendingCount_;
    // A pump that missed deadlines (the device thread held up) sends the newest frame due and
    // skips the older ones: the magnet gets the force of now at once, not a burst of stale
    // set-points that the newest would overwrite within microseconds. An on-time pump finds two
    // due only while the release latency comes down; both go (FrictionOut's frames, recorded).
    if (latePump && newerDue) {
      telemetry_.countSkippedFrame();
      continue;
    }
    telemetry_.frameOffset.record(std::abs(nowS - dueS));
    if (nowS - dueS > periodS) telemetry_.countLateFrame();
    applyFrameLocked(pending.frame, nowS, nowS);
    ++released;
  }
  return released;
}

void Device::pumpLocked(double nowS, double scheduledS) {
  // Announce the pump before looking at halted_ (both sequentially consistent): either
  // emergencyOff() sees this pump and waits for it, or this pump sees the halt.
  pumping_.store(true);
  struct PumpDone {
    std::atomic<bool>& flag;
    ~PumpDone() { flag.store(false); }
  } done{pumping_};
  if (halted_.load()) return;
  if (!(nowS > lastPumpS_)) return;

  if (offRequested_.exchange(false, std::memory_order_acq_rel)) applyOffRequestLocked(nowS, OffCause::kStop);
  // A silent watched client: the frames its orphaned synths still send go nowhere, and
  // nothing is recorded after the off.
  const bool clientSilent = !lockstep_ && clientSilentLocked(nowS);
  if (clientSilent) {
    ForceFrame dropped;
    while (frameQueue_.pop(dropped)) {
    }
  } else if (lockstep_) {
    ForceFrame frame;  // only frames whose push found the state busy
    while (frameQueue_.pop(frame)) applyLockstepFrameLocked(frame, nowS);
  } else {
    takeFramesLocked(nowS, scheduledS);
    settleLatencyLocked(nowS);
    const int released = releaseFramesLocked(nowS, nowS - scheduledS >= options_.pumpPeriodS);
    if (released > 0 || pendingCount_ > 0) telemetry_.countReleases(released);
    telemetry_.setReleaseLatency(releaseLatencyS_);
  }
  // Frames still waiting in the jitter buffer are coming: no trip while there are any, so a
  // long audio period does not make the watchdog chatter.
  if (!clientSilent && pendingCount_ == 0 && safety_.checkWatchdog(nowS)) {
    force_->driveOff();
    if (board_) board_->driveOff();
    telemetry_.countWatchdogTrip();
    telemetry_.setCommandedForce(safety_.commandedForceN());
    recorder_.writeOff(nowS, OffCause::kWatchdog);
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
      if (!clientSilent) recorder_.writeReport(nowS, pollBuffer_[i]);
      reportQueue_.push(pollBuffer_[i]);  // a full queue counts the overflow
    }
  } while (polled == kPollBatch);

  flushRecordingLocked();
  lastPumpS_ = nowS;
  lastPumpAtomicS_.store(nowS, std::memory_order_relaxed);
  telemetry_.countPump();
}

void Device::watchClient(double timeoutS) {
  heartbeat();
  clientTimeoutS_.store(timeoutS > 0.0 ? timeoutS : 0.0, std::memory_order_release);
}

bool Device::clientSilentLocked(double nowS) {
  const double timeoutS = clientTimeoutS_.load(std::memory_order_acquire);
  const bool silent = timeoutS > 0.0 && nowS - lastHeartbeatS_.load(std::memory_order_acquire) > timeoutS;
  if (!silent) {
    clientSilent_.store(false, std::memory_order_release);
    return false;
  }
  if (!clientSilent_.exchange(true, std::memory_order_acq_rel)) applyOffRequestLocked(nowS, OffCause::kClient);
  return true;
}

void Device::requestOff() {
  offRequested_.store(true, std::memory_order_release);
  if (!lockstep_ || isClosed()) return;
  std::unique_lock<PiMutex> lock(stateMutex_, std::try_to_lock);
  if (lock.owns_lock() && lastPumpS_ >= 0.0 && offRequested_.exchange(false, std::memory_order_acq_rel))
    applyOffRequestLocked(lastPumpS_, OffCause::kStop);
}

void Device::applyOffRequestLocked(double nowS, OffCause cause) {
  ForceFrame dropped;
  while (frameQueue_.pop(dropped)) {
  }
  pendingCount_ = 0;
  force_->driveOff();
  if (board_) board_->driveOff();
  safety_.resetToOff();
  telemetry_.countOrderlyOff();
  telemetry_.setCommandedForce(safety_.commandedForceN());
  recorder_.writeOff(nowS, cause);
}

void Device::close() {
  if (closed_.exchange(true, std::memory_order_acq_rel)) return;
  stopRequested_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  std::lock_guard<PiMutex> lock(stateMutex_);
  force_->driveOff();
  if (board_) board_->driveOff();
  safety_.resetToOff();
  pendingCount_ = 0;
  telemetry_.setCommandedForce(safety_.commandedForceN());
  recorder_.writeOff(std::max(lastPumpS_, 0.0), OffCause::kClose);
  recorder_.close();
}

int Device::popReports(MouseReport* out, int capacity, bool measureDelay) {
  int popped = 0;
  while (popped < capacity && reportQueue_.pop(out[popped])) ++popped;
  if (!lockstep_ && measureDelay && popped > 0) {
    const double now = nowS();
    for (int i = 0; i < popped; ++i) telemetry_.reportLatency.record(now - out[i].hostTimeS);
  }
  return popped;
}

double Device::nowS() const {
  if (lockstep_ || options_.externalPump) return lastPumpAtomicS_.load(std::memory_order_relaxed);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - startTime_).count();
}

bool Device::pushForceFrame(const ForceFrame& frame) {
  if (lockstep_ && !isClosed()) {
    std::unique_lock<PiMutex> lock(stateMutex_, std::try_to_lock);
    if (lock.owns_lock() && lastPumpS_ >= 0.0) {
      // Lockstep has one thread for both ends of the queue: earlier frames first.
      ForceFrame queued;
      while (frameQueue_.pop(queued)) applyLockstepFrameLocked(queued, lastPumpS_);
      applyLockstepFrameLocked(frame, lastPumpS_);
      return true;
    }
  }
  return frameQueue_.push(frame);
}

std::shared_ptr<ForceBackend> Device::attachBoard(std::shared_ptr<ForceBackend> board) {
  std::lock_guard<PiMutex> lock(stateMutex_);
  if (board_) board_->driveOff();
  if (board && !isClosed()) board->driveOff();  // from off; the next frame drives it
  std::swap(board_, board);
  return board;
}

std::shared_ptr<ForceBackend> Device::board() {
  std::lock_guard<PiMutex> lock(stateMutex_);
  return board_;
}

void Device::setCalibration(const CalibrationTable& table) {
  std::lock_guard<PiMutex> lock(stateMutex_);
  safety_.setCalibration(table);
}

uint64_t Device::driveLimitedFrames() {
  std::lock_guard<PiMutex> lock(stateMutex_);
  return safety_.driveLimitedFrames();
}

double Device::heatEstimate() {
  std::lock_guard<PiMutex> lock(stateMutex_);
  return safety_.heat();
}

TelemetrySnapshot Device::telemetry() const {
  TelemetrySnapshot snapshot = telemetry_.snapshot();
  snapshot.deviceThread = threadScheduling_.load();
  snapshot.mouseThread = mouse_->readerScheduling();
  snapshot.reportQueueOverflows = reportQueue_.overflows();
  snapshot.frameQueueOverflows = frameQueue_.overflows();
  return snapshot;
}

bool Device::startRecording(const std::string& path, std::string& error) {
  if (isClosed()) {
    error = "the device is closed";
    return false;
  }
  stopRecording();  // a recording in progress ends first, its file complete
  // Opened outside the lock (truncating a long file takes time); a realtime device's lines are
  // written by a thread of their own, so the disk never holds up the device thread.
  std::unique_ptr<RecordingWriter> writer =
      RecordingWriter::open(path, sessionHeader(spec_), !lockstep_, options_.thread.slot, error);
  if (!writer) return false;
  std::lock_guard<PiMutex> lock(stateMutex_);
  if (isClosed()) {
    error = "the device is closed";
    return false;
  }
  recorder_.attach(std::move(writer));
  return true;
}

void Device::stopRecording() {
  std::unique_ptr<RecordingWriter> writer;
  {
    std::lock_guard<PiMutex> lock(stateMutex_);
    writer = recorder_.detach();
  }
  if (!writer) return;
  writer->finish();  // the last writes, outside the lock: the device thread pumps on meanwhile
  std::lock_guard<PiMutex> lock(stateMutex_);
  recorder_.noteFinished(*writer);
  if (recorder_.takeFailure()) postDeviceMessage(("kfRecord: " + recorder_.error()).c_str());
}

bool Device::isRecording() {
  std::lock_guard<PiMutex> lock(stateMutex_);
  return recorder_.isOpen();
}

std::string Device::recordingError() {
  std::lock_guard<PiMutex> lock(stateMutex_);
  return recorder_.error();
}

void Device::flushRecordingLocked() {
  if (!recorder_.flush() && recorder_.takeFailure()) postDeviceMessage(("kfRecord: " + recorder_.error()).c_str());
}

void Device::haltInOrder() {
  std::lock_guard<PiMutex> lock(stateMutex_);  // pumps hold it: none is under way, none after
  halted_.store(true);
  applyOffRequestLocked(nowS(), OffCause::kQuit);
  flushRecordingLocked();
}

void Device::emergencyOff() noexcept {
  halted_.store(true);
  // A pump running on another thread may still command a force and write records: let it
  // finish first, for at most 50 ms (the handler may be running on that very thread).
  spinUntilFromSignal([this] { return !pumping_.load(); }, 50000000);
  force_->driveOffFromSignal();
  // The board's off set-point is queued for its event thread; if the process dies first, the
  // board's own watchdog turns the current off 20 ms after the last frame (PROTOCOL.md).
  if (ForceBackend* board = board_.get()) board->driveOffFromSignal();
  telemetry_.setCommandedForce(static_cast<float>(spec_.minForceN));
  recorder_.appendOffFromSignal(nowS());
}

}  // namespace kf
