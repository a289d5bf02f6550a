// Device: one opened device slot — a mouse backend, a force backend, the two SPSC queues to
// and from the audio thread, ForceSafety, Telemetry and an optional Recorder — and the
// device thread that pumps it every 1 ms in realtime. In lockstep mode (NRT rendering) there
// is no thread: the audio side calls pump(audioTimeS) itself, through the same code.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "DeviceSpec.hpp"
#include "ForceBackend.hpp"
#include "ForceSafety.hpp"
#include "MouseBackend.hpp"
#include "Report.hpp"
#include "SessionFile.hpp"
#include "SpscQueue.hpp"
#include "Telemetry.hpp"

namespace kf {

struct DeviceOptions {
  size_t reportQueueCapacity = 1024;  // 8 s of 125 Hz reports
  size_t frameQueueCapacity = 1024;   // 1 s of 1 kHz frames
  double pumpPeriodS = 0.001;         // realtime: how often the thread pumps
};

class Device {
 public:
  // The mouse and force backends may be one object (SimDevice) or two.
  Device(const DeviceSpec& spec, std::shared_ptr<MouseBackend> mouse, std::shared_ptr<ForceBackend> force,
         bool lockstep, DeviceOptions options = {});
  // Closes: stops and joins the thread, drives the magnet off.
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  // Realtime: starts the device thread; device time 0 is now. Lockstep: nothing.
  void start();
  // Stop flag, join, magnet off, recording closed. Idempotent; not from the audio thread.
  void close();

  // One round of work at device time nowS (lockstep: audio time, less the origin): force frames from the audio queue
  // through ForceSafety to the force backend, the watchdog, reports up to nowS into the audio queue, recording. Does
  // nothing for nowS <= the last pumped time (several UGens may call it), while the state is being changed (recording
  // started/stopped), after close, and in realtime mode (where the device thread is the only pumper).
  void pump(double nowS);

  // Audio side (one consumer / one producer thread): never allocate, lock or wait.
  // popReports also measures, in realtime, how long each report waited in the queue.
  int popReports(MouseReport* out, int capacity);
  bool pushForceFrame(const ForceFrame& frame);
  // The device clock: seconds since start() in realtime (steady clock, any thread, no lock);
  // in lockstep the last pumped time.
  double nowS() const;

  const DeviceSpec& spec() const { return spec_; }
  bool isLockstep() const { return lockstep_; }
  // Lockstep: the audio time at which the device opened, its time 0 (as a realtime device's
  // clock starts at open). pump() takes audio time and subtracts it. Set before first use.
  void setLockstepOriginS(double audioTimeS) { lockstepOriginS_ = audioTimeS; }
  double lockstepOriginS() const { return lockstepOriginS_; }
  bool isClosed() const { return closed_.load(std::memory_order_acquire); }
  TelemetrySnapshot telemetry() const;

  // From a non-realtime thread. Starts a kf-session file with the spec in its header.
  bool startRecording(const std::string& path, std::string& error);
  void stopRecording();

  MouseBackend& mouseBackend() { return *mouse_; }
  ForceBackend& forceBackend() { return *force_; }

 private:
  static constexpr int kPollBatch = 64;

  void pumpLocked(double nowS);
  void threadMain();

  const DeviceSpec spec_;
  const bool lockstep_;
  double lockstepOriginS_ = 0.0;
  const DeviceOptions options_;
  std::shared_ptr<MouseBackend> mouse_;
  std::shared_ptr<ForceBackend> force_;
  SpscQueue<MouseReport> reportQueue_;
  SpscQueue<ForceFrame> frameQueue_;
  Telemetry telemetry_;

  // Guards the pumped state below against start/stopRecording and close.
  std::mutex stateMutex_;
  ForceSafety safety_;
  Recorder recorder_;
  double lastPumpS_ = -1.0;
  double lastCommandS_ = 0.0;
  MouseReport pollBuffer_[kPollBatch];
  int64_t xCounts_ = 0;  // the puck's position since open (MouseReport::xCounts)
  int64_t yCounts_ = 0;

  std::chrono::steady_clock::time_point startTime_;  // device time 0; reset by start()
  std::atomic<double> lastPumpAtomicS_{0.0};         // lastPumpS_ for other threads
  std::thread thread_;
  std::atomic<bool> stopRequested_{false};
  std::atomic<bool> closed_{false};
};

}  // namespace kf
