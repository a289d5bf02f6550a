#include "mouse/RealMouseBackend.hpp"

#include <cstdio>

#include "core/threads/ThreadScheduling.hpp"
#include "mouse/MouseSelect.hpp"

namespace kf {

RealMouseBackend::RealMouseBackend() : originS_(monotonicNowS()), queue_(kQueueCapacity) {}

RealMouseBackend::~RealMouseBackend() { stop(); }

bool RealMouseBackend::openSelected(const std::vector<MouseInfo>& mice, const std::string& which, std::string& error,
                                    OpenFailure* why, const ThreadRequest& thread) {
  OpenFailure failure = OpenFailure::kNotFound;  // no such mouse, unless the open says otherwise
  MouseInfo info;
  const bool opened = selectMouse(mice, which, info, error) && openInfo(info, error, failure);
  if (why) *why = opened ? OpenFailure::kNone : failure;
  threadRequest_ = thread;
  if (opened) startReader();
  return opened;
}

void RealMouseBackend::startReader() {
  if (thread_.joinable()) return;
  state_.store(static_cast<int>(MouseState::kRunning), std::memory_order_release);
  // No signal meant for the process is handled on the reader: hid_read_timeout would return -1
  // from poll's EINTR, which reads as an unplug.
  thread_ = startThreadWithAsyncSignalsBlocked([this] { threadMain(); });
}

void RealMouseBackend::stop() {
  stopRequested_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  state_.store(static_cast<int>(MouseState::kStopped), std::memory_order_release);
}

void RealMouseBackend::threadMain() {
  readerScheduling_.store(scheduleThisThread("mouse", threadRequest_));
  bool open = true;
  while (!stopRequested_.load(std::memory_order_acquire)) {
    if (!open) {
      // Unplugged: wait for a re-open request, checking the stop flag as often as a read would.
      if (!reopenRequested_.exchange(false, std::memory_order_acq_rel)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(kReadTimeoutMs));
        continue;
      }
      std::string error;
      if (!reopenHandle(error)) {
        setError(error);
        continue;
      }
      open = true;
      reopens_.fetch_add(1, std::memory_order_relaxed);
      state_.store(static_cast<int>(MouseState::kRunning), std::memory_order_release);
      continue;
    }
    if (readSome(kReadTimeoutMs) < 0) {
      closeHandle();
      open = false;
      unplugs_.fetch_add(1, std::memory_order_relaxed);
      state_.store(static_cast<int>(MouseState::kUnplugged), std::memory_order_release);
    }
  }
  if (open) closeHandle();
}

void RealMouseBackend::emit(MouseReport report) {
  if (report.flags & kSaturated) countSaturated();
  if (rate_.addReport(report.deviceTimeS)) rateHz_.store(rate_.rateHz(), std::memory_order_relaxed);
  reports_.fetch_add(1, std::memory_order_relaxed);
  queue_.push(report);  // a full queue counts the overflow
}

int RealMouseBackend::pollReports(double, MouseReport* out, int capacity) {
  int written = 0;
  while (written < capacity && queue_.pop(out[written])) ++written;
  return written;
}

MouseCounters RealMouseBackend::counters() const {
  MouseCounters c;
  c.reports = reports_.load(std::memory_order_relaxed);
  c.lossEvents = lossEvents_.load(std::memory_order_relaxed);
  c.lossesEstimated = lossesEstimated();
  c.saturated = saturated_.load(std::memory_order_relaxed);
  c.malformed = malformed_.load(std::memory_order_relaxed);
  c.queueOverflows = queue_.overflows();
  c.unplugs = unplugs_.load(std::memory_order_relaxed);
  c.reopens = reopens_.load(std::memory_order_relaxed);
  c.measuredRateHz = rateHz_.load(std::memory_order_relaxed);
  c.state = state();
  return c;
}

void RealMouseBackend::setError(const std::string& error) {
  std::lock_guard<std::mutex> lock(textMutex_);
  lastError_ = error;
}

std::string RealMouseBackend::lastError() const {
  std::lock_guard<std::mutex> lock(textMutex_);
  return lastError_;
}

void RealMouseBackend::publishInfo(const MouseInfo& info) {
  std::lock_guard<std::mutex> lock(textMutex_);
  info_ = info;
}

MouseInfo RealMouseBackend::info() const {
  std::lock_guard<std::mutex> lock(textMutex_);
  return info_;
}

std::string RealMouseBackend::describe() const {
  const MouseCounters c = counters();
  const MouseInfo mouse = info();
  const char* state = c.state == MouseState::kRunning     ? "running"
                      : c.state == MouseState::kUnplugged ? "UNPLUGGED (position held; kfReopenMouse to re-open)"
                                                          : "stopped";
  char line[512];
  std::snprintf(line, sizeof(line),
                "%s mouse %s (%04x:%04x %s): %s, reports %llu, measured rate %.1f Hz, losses %llu%s, "
                "saturated %llu, malformed %llu, overflows %llu, unplugs %llu, re-opens %llu",
                kindName().c_str(), mouse.path.c_str(), mouse.vendorId, mouse.productId, mouse.product.c_str(), state,
                static_cast<unsigned long long>(c.reports), c.measuredRateHz,
                static_cast<unsigned long long>(c.lossEvents), c.lossesEstimated ? " (estimated: full queues)" : "",
                static_cast<unsigned long long>(c.saturated), static_cast<unsigned long long>(c.malformed),
                static_cast<unsigned long long>(c.queueOverflows), static_cast<unsigned long long>(c.unplugs),
                static_cast<unsigned long long>(c.reopens));
  std::string out = line;
  const std::string error = lastError();
  if (!error.empty()) out += "; last error: " + error;
  return out;
}

}  // namespace kf
