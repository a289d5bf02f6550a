// RealMouseBackend: what the hidapi and evdev backends share — a reader thread that owns the
// open handle (it alone reads, closes and re-opens it: nothing is ever closed during a read),
// blocks in short reads with a stop flag, stamps reports and passes them to pollReports
// through an SPSC queue, and counts what went wrong. Unplug (a read error) is seen within one
// read timeout: the handle is closed, reports stop (the position holds), the state says so,
// and requestReopen() makes the thread look for the same mouse again.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "ReportRateEstimator.hpp"
#include "core/MouseBackend.hpp"
#include "core/SpscQueue.hpp"
#include "mouse/MouseIo.hpp"

namespace kf {

enum class MouseState : int { kRunning = 0, kUnplugged = 1, kStopped = 2 };

struct MouseCounters {
  uint64_t reports = 0;          // mouse reports passed on
  uint64_t lossEvents = 0;       // times reports were lost (SYN_DROPPED, a full kernel queue)
  bool lossesEstimated = false;  // hidraw: a full queue is taken for a loss (it may not be one)
  uint64_t saturated = 0;        // reports with a delta at its field's limit (excess lost)
  uint64_t malformed = 0;        // reads that were not a whole mouse report (short, other ID)
  uint64_t queueOverflows = 0;   // reports the device thread did not take in time
  uint64_t unplugs = 0;
  uint64_t reopens = 0;
  double measuredRateHz = 0.0;  // 0 until enough reports (ReportRateEstimator)
  MouseState state = MouseState::kStopped;
};

// Seconds on the monotonic clock (steady_clock is CLOCK_MONOTONIC on Linux, the clock evdev
// stamps with after EVIOCSCLOCKID).
inline double monotonicNowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

class RealMouseBackend : public MouseBackend {
 public:
  static constexpr int kReadTimeoutMs = 10;       // stop and unplug are seen within this
  static constexpr size_t kQueueCapacity = 8192;  // 1 s at 8 kHz

  ~RealMouseBackend() override;

  // Starts the reader thread with the handle the subclass opened. Once.
  void startReader();
  // Stop flag and join; the thread closes the handle. Idempotent.
  void stop();

  // Reports stamped on the monotonic clock less originS() (seconds since the backend opened).
  // Real reports arrive in real time: every report received so far is written.
  int pollReports(double untilTimeS, MouseReport* out, int capacity) override;

  void requestReopen() { reopenRequested_.store(true, std::memory_order_release); }
  MouseState state() const { return static_cast<MouseState>(state_.load(std::memory_order_acquire)); }
  MouseCounters counters() const;
  std::string lastError() const;
  double originS() const { return originS_; }
  // One line for kfStatus.
  std::string describe() const;
  std::string statusLine() const override { return describe(); }
  bool connected() const override { return state() != MouseState::kUnplugged; }
  ThreadScheduling readerScheduling() const override { return readerScheduling_.load(); }
  virtual std::string kindName() const = 0;
  // True when the kernel does not say it dropped reports and lossEvents is inferred.
  virtual bool lossesEstimated() const { return false; }
  // The mouse open now (it may change at a re-open). Any non-realtime thread.
  MouseInfo info() const;

 protected:
  RealMouseBackend();

  // Reader thread only, with an open handle: waits up to timeoutMs for input and emits the
  // reports read. 1: read something, 0: timeout, -1: the device is gone (unplugged).
  virtual int readSome(int timeoutMs) = 0;
  virtual void closeHandle() = 0;
  // Reader thread: finds the same mouse again and opens it; false with a message.
  virtual bool reopenHandle(std::string& error) = 0;
  // Opens the handle of this mouse (at open and re-open); false with a message and why.
  virtual bool openInfo(const MouseInfo& info, std::string& error, OpenFailure& why) = 0;

  // Every kind's open(), once its API has listed `mice`: selects `which` (MouseSelect), opens
  // it and starts the reader, scheduled as `thread` asks (named kf-mouse-<slot>). False with a
  // message; *why (if given) says why.
  bool openSelected(const std::vector<MouseInfo>& mice, const std::string& which, std::string& error, OpenFailure* why,
                    const ThreadRequest& thread);

  void emit(MouseReport report);  // reader thread; counts, measures, queues
  void countLoss() { lossEvents_.fetch_add(1, std::memory_order_relaxed); }
  void countMalformed() { malformed_.fetch_add(1, std::memory_order_relaxed); }
  void countSaturated() { saturated_.fetch_add(1, std::memory_order_relaxed); }
  void setError(const std::string& error);
  void publishInfo(const MouseInfo& info);  // for info() and describe()

 private:
  void threadMain();

  const double originS_;
  SpscQueue<MouseReport> queue_;
  ReportRateEstimator rate_;
  std::thread thread_;
  ThreadRequest threadRequest_;
  ThreadSchedulingCell readerScheduling_;
  std::atomic<bool> stopRequested_{false};
  std::atomic<bool> reopenRequested_{false};
  std::atomic<int> state_{static_cast<int>(MouseState::kStopped)};
  std::atomic<uint64_t> reports_{0}, lossEvents_{0}, saturated_{0}, malformed_{0}, unplugs_{0}, reopens_{0};
  std::atomic<double> rateHz_{0.0};
  mutable std::mutex textMutex_;  // not the audio thread's: NRT and the reader only
  std::string lastError_;
  MouseInfo info_;
};

}  // namespace kf
