// Fakes of the hidapi and evdev seams (device/MouseIo.hpp) that play a hid-recorder file in
// real time, as the kernel would hand it to a reader, and fail as the real calls do:
//  - reports become due at plug-in (the first open) + leadS + (recorded time - startS) +
//    injected jitter, on the monotonic clock; a read blocks until one is due or its timeout passes (then 0);
//  - the kernel's per-reader queue is bounded: hidraw keeps 64 reports and drops new ones
//    when full; evdev keeps 64 events and, on overflow, throws the queue away and leaves
//    SYN_DROPPED plus the newest event (drivers/input/evdev.c); a stall of the reader
//    (stallAtS / stallForS) lets it fill;
//  - short reads: hid reports cut to a few bytes (shortReportEvery); evdev reads that return
//    at most maxEventsPerRead events, splitting packets between reads;
//  - unplug at unplugAtS: hid reads return -1, evdev reads -1 with ENODEV, and the device is
//    gone from enumeration until replugAtS;
//  - EACCES: open fails with the permission message and OpenFailure::kPermission.
// evdev events are derived from the reports: REL_X, REL_Y (when non-zero), BTN_* changes,
// SYN_REPORT, all stamped with the report's due time in whole microseconds (as input_event).
#pragma once

#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "HidRecorderFile.hpp"
#include "MouseIo.hpp"
#include "RealMouseBackend.hpp"

namespace kf::test {

struct FakeMouseScript {
  HidRecording recording;
  double startS = 0.0;                   // recorded time that plays at plug-in + leadS
  double leadS = 0.05;                   // so that the first report comes after the open
  double endS = 1e9;                     // recorded time after which nothing more plays
  std::vector<double> jitterS;           // per report (cycled), added to its due time
  double unplugAtS = 1e9;                // since plug-in
  double replugAtS = 1e9;                // since plug-in; reports due while away are lost
  double stallAtS = 1e9, stallForS = 0;  // since plug-in: the reader is held this long
  int shortReportEvery = 0;              // hid: every n-th report arrives cut to 3 bytes
  int maxEventsPerRead = 64;             // evdev
  // The kernel's queue per reader: hidraw 64 reports, evdev 64 events for a mouse. Tests not
  // about loss raise it, so that their reader, descheduled on a loaded machine, loses nothing.
  size_t kernelQueue = 64;
  bool denyAccess = false;  // EACCES on open
  std::string path = "/dev/hidraw7";
};

// The timeline both fakes share: what is due when, from one plug-in time.
class FakeTimeline {
 public:
  explicit FakeTimeline(FakeMouseScript script) : script_(std::move(script)) {
    for (const HidRecordedEvent& event : script_.recording.events) {
      if (event.timeS < script_.startS || event.timeS > script_.endS) continue;
      const double jitter = script_.jitterS.empty() ? 0.0 : script_.jitterS[played_.size() % script_.jitterS.size()];
      played_.push_back({script_.leadS + event.timeS - script_.startS + jitter, event.bytes});
    }
  }
  struct Due {
    double sincePlugS;  // when the kernel has it
    std::vector<uint8_t> bytes;
  };
  const FakeMouseScript& script() const { return script_; }
  const std::vector<Due>& played() const { return played_; }
  // The mouse is plugged in at the first open, so that a test slowed down before it loses
  // nothing (a real reader sees only what comes after its open).
  void plugInOnce() {
    if (plugS_ == 0.0) plugS_ = monotonicNowS();
  }
  double plugS() const { return plugS_; }  // monotonic
  double nowSincePlugS() const { return plugS_ == 0.0 ? 0.0 : monotonicNowS() - plugS_; }
  bool present(double sinceS) const { return sinceS < script_.unplugAtS || sinceS >= script_.replugAtS; }
  void sleepUntilSincePlug(double sinceS) const {
    const double waitS = sinceS - nowSincePlugS();
    if (waitS > 0) std::this_thread::sleep_for(std::chrono::duration<double>(waitS));
  }

 private:
  FakeMouseScript script_;
  double plugS_ = 0.0;
  std::vector<Due> played_;
};

// --- hidapi -------------------------------------------------------------------------------

class FakeHidHandle : public HidHandle {
 public:
  explicit FakeHidHandle(std::shared_ptr<FakeTimeline> timeline)
      : timeline_(std::move(timeline)), openedS_(timeline_->nowSincePlugS()) {
    // A new reader sees only what comes after its open.
    while (next_ < timeline_->played().size() && timeline_->played()[next_].sincePlugS < openedS_) ++next_;
  }
  int readTimeout(uint8_t* buffer, size_t capacity, int timeoutMs) override {
    const FakeMouseScript& s = timeline_->script();
    if (!stalled_ && timeline_->nowSincePlugS() >= s.stallAtS) {
      stalled_ = true;
      timeline_->sleepUntilSincePlug(s.stallAtS + s.stallForS);
    }
    const double deadlineS = timeline_->nowSincePlugS() + timeoutMs * 1e-3;
    for (;;) {
      const double nowS = timeline_->nowSincePlugS();
      if (gone(nowS)) {
        error_ = "hid_read_timeout: unexpected poll error (device disconnected)";
        return -1;
      }
      refill(nowS);
      if (!queue_.empty()) {
        std::vector<uint8_t> bytes = std::move(queue_.front());
        queue_.pop_front();
        const size_t n = std::min(bytes.size(), capacity);
        std::copy_n(bytes.begin(), n, buffer);
        return static_cast<int>(n);
      }
      if (nowS >= deadlineS) return 0;
      double wakeS = std::min(deadlineS, s.unplugAtS);
      if (next_ < timeline_->played().size()) wakeS = std::min(wakeS, timeline_->played()[next_].sincePlugS);
      timeline_->sleepUntilSincePlug(std::max(wakeS, nowS + 1e-5));
    }
  }
  std::string lastError() override { return error_; }
  bool reportDescriptor(std::vector<uint8_t>& out, std::string&) override {
    out = timeline_->script().recording.descriptor;
    return true;
  }
  int kernelDrops() const { return drops_; }

 private:
  // A handle opened before an unplug stays dead after the replug (a new node, a new open).
  bool gone(double nowS) const {
    return nowS >= timeline_->script().unplugAtS && openedS_ < timeline_->script().unplugAtS;
  }
  void refill(double nowS) {
    const auto& played = timeline_->played();
    while (next_ < played.size() && played[next_].sincePlugS <= nowS) {
      const auto& due = played[next_++];
      if (!timeline_->present(due.sincePlugS)) continue;
      if (queue_.size() >= timeline_->script().kernelQueue) {  // hidraw: full, the new report is dropped
        ++drops_;
        continue;
      }
      ++count_;
      std::vector<uint8_t> bytes = due.bytes;
      if (timeline_->script().shortReportEvery > 0 && count_ % timeline_->script().shortReportEvery == 0)
        bytes.resize(3);
      queue_.push_back(std::move(bytes));
    }
  }

  std::shared_ptr<FakeTimeline> timeline_;
  double openedS_;
  size_t next_ = 0;
  std::deque<std::vector<uint8_t>> queue_;
  std::string error_;
  bool stalled_ = false;
  int drops_ = 0;
  int count_ = 0;
};

class FakeHidApi : public HidApi {
 public:
  explicit FakeHidApi(FakeMouseScript script) : timeline(std::make_shared<FakeTimeline>(std::move(script))) {}
  bool enumerateMice(std::vector<MouseInfo>& out, std::string&) override {
    out.clear();
    if (!timeline->present(timeline->nowSincePlugS())) return true;
    MouseInfo info;
    info.path = timeline->script().path;
    info.vendorId = static_cast<uint16_t>(timeline->script().recording.vendorId);
    info.productId = static_cast<uint16_t>(timeline->script().recording.productId);
    info.product = timeline->script().recording.name;
    info.interfaceNumber = 0;
    info.usagePage = 1;
    info.usage = 2;
    out.push_back(info);
    return true;
  }
  std::unique_ptr<HidHandle> openPath(const std::string& path, std::string& error, OpenFailure& why) override {
    if (timeline->script().denyAccess) {
      why = OpenFailure::kPermission;
      error = permissionFix(path);
      return nullptr;
    }
    if (path != timeline->script().path || !timeline->present(timeline->nowSincePlugS())) {
      why = OpenFailure::kNotFound;
      error = path + ": No such file or directory";
      return nullptr;
    }
    why = OpenFailure::kNone;
    timeline->plugInOnce();
    return std::make_unique<FakeHidHandle>(timeline);
  }
  std::shared_ptr<FakeTimeline> timeline;
};

// --- evdev --------------------------------------------------------------------------------

class FakeEvdevHandle : public EvdevHandle {
 public:
  explicit FakeEvdevHandle(std::shared_ptr<FakeTimeline> timeline)
      : timeline_(std::move(timeline)), openedS_(timeline_->nowSincePlugS()) {
    while (next_ < timeline_->played().size() && timeline_->played()[next_].sincePlugS < openedS_) ++next_;
  }
  bool setMonotonicClock(std::string&) override {
    monotonic_ = true;
    return true;
  }
  bool grab(bool on, std::string&) override {
    grabbed = on;
    return true;
  }
  std::string name() override { return timeline_->script().recording.name; }
  bool id(uint16_t& vendorId, uint16_t& productId) override {
    vendorId = static_cast<uint16_t>(timeline_->script().recording.vendorId);
    productId = static_cast<uint16_t>(timeline_->script().recording.productId);
    return true;
  }
  int read(EvdevEvent* out, int capacity, int timeoutMs, int* errnoOut) override {
    const FakeMouseScript& s = timeline_->script();
    if (!stalled_ && timeline_->nowSincePlugS() >= s.stallAtS) {
      stalled_ = true;
      timeline_->sleepUntilSincePlug(s.stallAtS + s.stallForS);
    }
    const double deadlineS = timeline_->nowSincePlugS() + timeoutMs * 1e-3;
    for (;;) {
      const double nowS = timeline_->nowSincePlugS();
      if (nowS >= s.unplugAtS && openedS_ < s.unplugAtS) {
        *errnoOut = ENODEV;
        return -1;
      }
      refill(nowS);
      if (!queue_.empty()) {
        int n = 0;
        const int limit = std::min(capacity, s.maxEventsPerRead);
        while (n < limit && !queue_.empty()) {
          out[n++] = queue_.front();
          queue_.pop_front();
          if (out[n - 1].type == 0x00 && out[n - 1].code == 3) ++syncDropped_;
        }
        return n;
      }
      if (nowS >= deadlineS) return 0;
      double wakeS = std::min(deadlineS, s.unplugAtS);
      if (next_ < timeline_->played().size()) wakeS = std::min(wakeS, timeline_->played()[next_].sincePlugS);
      timeline_->sleepUntilSincePlug(std::max(wakeS, nowS + 1e-5));
    }
  }
  bool grabbed = false;
  int syncDropped() const { return syncDropped_; }  // SYN_DROPPED events handed to the reader

  // The kernel's stamp of a report due at sinceS: whole microseconds of CLOCK_MONOTONIC.
  static double stampS(const FakeTimeline& timeline, double sinceS) {
    return std::floor((timeline.plugS() + sinceS) * 1e6) * 1e-6;
  }

 private:
  void push(const EvdevEvent& event) {
    queue_.push_back(event);
    if (queue_.size() >= timeline_->script().kernelQueue) {  // evdev: drop all, keep SYN_DROPPED + newest
      queue_.clear();
      queue_.push_back(EvdevEvent{event.timeS, 0x00, 3, 0});
      queue_.push_back(event);
    }
  }
  void refill(double nowS) {
    const auto& played = timeline_->played();
    while (next_ < played.size() && played[next_].sincePlugS <= nowS) {
      const auto& due = played[next_++];
      if (!timeline_->present(due.sincePlugS)) continue;
      const std::vector<uint8_t>& b = due.bytes;  // the Genius report 1: id, buttons, X, Y int16
      if (b.size() < 6 || b[0] != 1) continue;
      const double t = monotonic_ ? stampS(*timeline_, due.sincePlugS) : 1.7e9 + due.sincePlugS;
      const int16_t dx = static_cast<int16_t>(b[2] | b[3] << 8), dy = static_cast<int16_t>(b[4] | b[5] << 8);
      if (dx != 0) push({t, 0x02, 0x00, dx});
      if (dy != 0) push({t, 0x02, 0x01, dy});
      for (int bit = 0; bit < 5; ++bit)
        if (((b[1] ^ buttons_) >> bit) & 1) push({t, 0x01, static_cast<uint16_t>(0x110 + bit), (b[1] >> bit) & 1});
      buttons_ = b[1];
      push({t, 0x00, 0x00, 0});
    }
  }

  std::shared_ptr<FakeTimeline> timeline_;
  double openedS_;
  size_t next_ = 0;
  std::deque<EvdevEvent> queue_;
  uint8_t buttons_ = 0;
  bool monotonic_ = false;
  bool stalled_ = false;
  int syncDropped_ = 0;
};

class FakeEvdevApi : public EvdevApi {
 public:
  explicit FakeEvdevApi(FakeMouseScript script) : timeline(std::make_shared<FakeTimeline>(std::move(script))) {}
  bool enumerateMice(std::vector<MouseInfo>& out, std::string&) override {
    out.clear();
    if (!timeline->present(timeline->nowSincePlugS())) return true;
    MouseInfo info;
    info.path = "/dev/input/event9";
    info.vendorId = static_cast<uint16_t>(timeline->script().recording.vendorId);
    info.productId = static_cast<uint16_t>(timeline->script().recording.productId);
    info.product = timeline->script().recording.name;
    out.push_back(info);
    return true;
  }
  std::unique_ptr<EvdevHandle> open(const std::string& path, std::string& error, OpenFailure& why) override {
    if (timeline->script().denyAccess) {
      why = OpenFailure::kPermission;
      error = permissionFix(path);
      return nullptr;
    }
    why = OpenFailure::kNone;
    timeline->plugInOnce();
    auto handle = std::make_unique<FakeEvdevHandle>(timeline);
    lastHandle = handle.get();
    return handle;
  }
  std::shared_ptr<FakeTimeline> timeline;
  FakeEvdevHandle* lastHandle = nullptr;  // for inspection while it lives
};

}  // namespace kf::test
