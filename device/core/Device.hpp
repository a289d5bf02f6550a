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
#include <vector>

#include "core/ForceBackend.hpp"
#include "core/MouseBackend.hpp"
#include "core/SpscQueue.hpp"
#include "core/Telemetry.hpp"
#include "core/files/SessionFile.hpp"
#include "core/force/CalibrationTable.hpp"
#include "core/force/ForceSafety.hpp"
#include "core/spec/DeviceSpec.hpp"
#include "core/spec/Report.hpp"
#include "core/threads/PiMutex.hpp"

namespace kf {

struct DeviceOptions {
  size_t reportQueueCapacity = 1024;  // 8 s of 125 Hz reports
  size_t frameQueueCapacity = 1024;   // 1 s of 1 kHz frames
  double pumpPeriodS = 0.001;         // realtime: how often the thread pumps
  // Realtime: each force frame goes to the magnet at its own device time, its start plus a
  // release latency (a jitter buffer), so the magnet gets one set-point per ms as FrictionOut
  // framed them. The latency is what the frames are measured to need, from the first frame on;
  // before it, the estimate of what one can need: its own period, the audio period that carries
  // it (audioPeriodS, the host's; 0 unknown) and the pump that picks it up. A frame later than the latency (a long
  // audio period, a late audio thread) raises it to its lateness (so it goes out now), up to
  // maxForceLatencyS: the frames after it keep their spacing instead of coming in bursts. Once
  // no frame of the last 0.5 to 1 s needed it, it comes back down by 5 % of the time passing
  // (frames 0.95 ms apart meanwhile), to what they needed, never below one frame period (a
  // frame goes out complete). So a stall does not keep it raised, long audio periods, whose
  // every burst needs it, keep it, and with realtime threads it stays small.
  double audioPeriodS = 0.0;
  double maxForceLatencyS = 0.1;
  // The device thread (realtime): its name's slot and its priority (ThreadScheduling). The
  // mouse reader and USB threads of the device take the same request.
  ThreadRequest thread;
  // Tests: a realtime device (jitter buffer, watchdog) without its thread, pumped by the
  // caller through pump(nowS) on a clock of its own (nowS() is the last pumped time).
  bool externalPump = false;
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
  // scheduledS (externalPump): when this pump was due, if it runs late, as the device thread
  // passes the deadline it missed; frames are judged late against it, so the pumper's own
  // lateness does not raise the release latency (the stale frames are skipped instead).
  void pump(double nowS, double scheduledS = -1.0);

  // Audio side (one consumer / one producer thread): never allocate, lock or wait.
  // popReports also measures, in realtime, how long each report waited in the queue for its
  // reader; measureDelay false: no reader was reading while they came (a slot's first read, or
  // the first after its readers were all gone), so their wait is no reader's delay.
  int popReports(MouseReport* out, int capacity, bool measureDelay = true);
  // Realtime: queued for the device thread. Lockstep: the audio thread is the pumper, so the
  // frame goes through the safety path at once (try_lock; queued when that fails), and
  // commandedForceN() tells at once what it became.
  bool pushForceFrame(const ForceFrame& frame);
  // Magnet off now, as an orderly stop asks (the last FrictionOut of the slot freed: a synth
  // freed, Cmd-., s.freeAll, /quit): any thread, never waits. Realtime: the next pump (within a
  // pump period) drops the frames not yet sent, drives the magnet off and records the off,
  // before the watchdog would. Lockstep: at once (try_lock; else at the next pump). Frames that
  // come after it drive the magnet again.
  void requestOff();
  // The force last sent to the magnet after the safety path (watchdog trips and close too).
  float commandedForceN() const { return telemetry_.commandedForceN(); }
  // Audio thread: how long one block of a writer (FrictionOut) took, for telemetry (no lock).
  void noteAudioCall(double seconds) { telemetry_.recordAudioCall(seconds); }
  // The device clock: seconds since start() in realtime (steady clock, any thread, no lock);
  // in lockstep the last pumped time.
  double nowS() const;

  const DeviceSpec& spec() const { return spec_; }
  const DeviceOptions& options() const { return options_; }
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
  // Why the last recording stopped by itself (a write error, also posted), or empty.
  std::string recordingError();
  // A recording is open and has not stopped by itself. From a non-realtime thread.
  bool isRecording();

  // The client watch (realtime only; a study session's sclang keeps it alive): once no
  // heartbeat() has come for timeoutS of device time, the next pump drives the magnet off,
  // drops the frames still coming and records the off (cause "client") as the recording's last
  // line; nothing more is recorded or driven while the client stays silent. A heartbeat brings
  // both back. timeoutS 0: no watch (the default: a live coder's synths play on without sclang,
  // as SC's servers do). From a non-realtime thread; heartbeat() from any thread, never waits.
  void watchClient(double timeoutS);
  void heartbeat() { lastHeartbeatS_.store(nowS(), std::memory_order_release); }
  // The watched client has been silent past its timeout (the magnet held off).
  bool clientSilent() const { return clientSilent_.load(std::memory_order_acquire); }
  // The device thread stopped on a backend's exception (failThread): nothing pumps the device
  // any more, its magnet is off and its recording closed, until it is opened again.
  bool threadFailed() const { return threadFailed_.load(std::memory_order_acquire); }

  // Async-signal-safe, from any thread (the handlers of host/ExitSafety.cpp): drives the
  // magnet off without a lock and appends an off record to the recording; no pump runs after
  // it (one under way on another thread is waited for, at most 50 ms). The process is on its
  // way out; nothing else is cleaned up.
  void emergencyOff() noexcept;
  // From a non-realtime thread, the process ending in order (the server's /quit, before its audio
  // stops): the magnet off now, the off recorded after every line before it, and no pump after
  // it, so the frames the audio still sends are never applied.
  void haltInOrder();

  // From a non-realtime thread: an extra force backend (the friction board) that gets every
  // command and drive-off the device's own backend gets, from the next frame on. Null
  // detaches the board, after driving it off. Returns the board attached before.
  std::shared_ptr<ForceBackend> attachBoard(std::shared_ptr<ForceBackend> board);
  std::shared_ptr<ForceBackend> board();
  // From a non-realtime thread: the board's calibration table for the force path.
  void setCalibration(const CalibrationTable& table);
  // Frames the hard drive limit or the heat estimate lowered, and the heat estimate now.
  uint64_t driveLimitedFrames();
  double heatEstimate();

  MouseBackend& mouseBackend() { return *mouse_; }
  ForceBackend& forceBackend() { return *force_; }

 private:
  static constexpr int kPollBatch = 64;
  static constexpr double kLatencyWindowS = 0.5;     // how long a frame's need is remembered
  static constexpr double kLatencyDecayRate = 0.05;  // s per s: frames 5 % closer meanwhile

  struct PendingFrame {
    ForceFrame frame;
    double startS;  // the frame's start on the device clock
  };

  void pumpLocked(double nowS, double scheduledS);
  // requestOff() in the pump (and haltInOrder): the frames not sent dropped, the magnet off, the
  // off recorded with its cause.
  void applyOffRequestLocked(double nowS, OffCause cause);
  // The client watch in the pump: true while the watched client is silent (nothing driven or
  // recorded); the off and its record once, as it falls silent.
  bool clientSilentLocked(double nowS);
  // Hands the recording's new lines to its writer; a recording that failed is posted, once.
  void flushRecordingLocked();
  void threadMain();
  // The device thread caught an exception from a backend: magnet off, recording closed.
  void failThread(const char* what) noexcept;
  // One frame through ForceSafety to the backend, telemetry and recording.
  void applyFrameLocked(const ForceFrame& frame, double commandS, double nowS);
  void applyLockstepFrameLocked(const ForceFrame& frame, double nowS);
  // Realtime jitter buffer: queue -> pending (with release times), then the due ones out.
  void takeFramesLocked(double nowS, double scheduledS);
  void settleLatencyLocked(double nowS);
  int releaseFramesLocked(double nowS, bool latePump);

  const DeviceSpec spec_;
  const bool lockstep_;
  double lockstepOriginS_ = 0.0;
  const DeviceOptions options_;
  std::shared_ptr<MouseBackend> mouse_;
  std::shared_ptr<ForceBackend> force_;
  std::shared_ptr<ForceBackend> board_;  // under stateMutex_
  SpscQueue<MouseReport> reportQueue_;
  SpscQueue<ForceFrame> frameQueue_;
  Telemetry telemetry_;

  // Guards the pumped state below against start/stopRecording, the board, status and close:
  // priority inheritance, since those come from normal-priority threads (PiMutex.hpp).
  PiMutex stateMutex_;
  ForceSafety safety_;
  Recorder recorder_;
  double lastPumpS_ = -1.0;
  double lastCommandS_ = 0.0;
  MouseReport pollBuffer_[kPollBatch];
  std::vector<PendingFrame> pending_;  // ring, frameQueueCapacity
  size_t pendingHead_ = 0;
  size_t pendingCount_ = 0;
  double releaseLatencyS_;
  bool latencyMeasured_ = false;  // a frame has set releaseLatencyS_
  // The largest lateness of the frames taken in this window and the one before (seconds).
  double windowLatenessS_ = 0.0, previousWindowLatenessS_ = 0.0;
  double windowEndS_ = 0.0;
  int64_t xCounts_ = 0;  // the puck's position since open (MouseReport::xCounts)
  int64_t yCounts_ = 0;

  std::chrono::steady_clock::time_point startTime_;  // device time 0; reset by start()
  std::atomic<double> lastPumpAtomicS_{0.0};         // lastPumpS_ for other threads
  std::thread thread_;
  ThreadSchedulingCell threadScheduling_;
  bool memoryLocked_ = false;  // the device's own memory, by start()
  std::atomic<bool> stopRequested_{false};
  std::atomic<double> clientTimeoutS_{0.0};  // watchClient's; 0 no watch
  std::atomic<double> lastHeartbeatS_{0.0};  // device time of the last heartbeat()
  std::atomic<bool> clientSilent_{false};
  std::atomic<bool> threadFailed_{false};
  std::atomic<bool> offRequested_{false};  // requestOff()
  std::atomic<bool> closed_{false};
  // emergencyOff() and haltInOrder(): no pump runs any more (halted_), and none is under way (pumping_).
  std::atomic<bool> halted_{false};
  std::atomic<bool> pumping_{false};
};

}  // namespace kf
