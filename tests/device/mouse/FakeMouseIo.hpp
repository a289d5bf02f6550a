// Fakes of the hidapi and evdev seams (device/mouse/MouseIo.hpp) that play a hid-recorder file in
// real time, as the kernel would hand it to a reader, and fail as the real calls do:
//  - reports become due at plug-in (the first open) + leadS + (recorded time - startS) +
//    injected jitter, on the monotonic clock; a read blocks until one is due or its timeout passes (then 0);
//  - the kernel's per-reader queue is bounded: hidraw's ring of 64 slots holds 63 reports and
//    drops new ones when full (drivers/hid/hidraw.c); evdev keeps 64 events and, on overflow,
//    throws the queue away and leaves SYN_DROPPED plus the newest event (drivers/input/evdev.c),
//    and EVIOCGKEY answers the buttons down now; a stall of the reader
//    (stallAtS / stallForS) lets it fill;
//  - short reads: hid reports cut to a few bytes (shortReportEvery); evdev reads that return
//    at most maxEventsPerRead events, splitting packets between reads;
//  - unplug at unplugAtS: hid reads return -1, evdev reads -1 with ENODEV, and the device is
//    gone from enumeration until replugAtS (then, hidapi, at replugPath if one is given);
//  - other devices listed with it (`others`: a twin of the same make in another port, a
//    built-in trackpoint), which cannot be opened;
//  - EACCES: open fails with the permission message and OpenFailure::kPermission.
// evdev events are derived from the reports: REL_X, REL_Y (when non-zero), BTN_* changes,
// SYN_REPORT, all stamped with the report's due time in whole microseconds (as input_event).
#pragma once

#include <atomic>
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

#include "mouse/MouseIo.hpp"
#include "mouse/RealMouseBackend.hpp"
#include "recordings/HidRecorderFile.hpp"

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
  // The kernel's ring per reader: hidraw 64 slots (63 reports), evdev 64 events for a mouse. Tests not
  // about loss raise it, so that their reader, descheduled on a loaded machine, loses nothing.
  size_t kernelQueue = 64;
  bool denyAccess = false;  // EACCES on open
  std::string path = "/dev/hidraw7";
  std::string replugPath;  // hidapi: its node after the replug ("" the same)
  std::string busPath = "pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.0/0003:0458:0138";
  std::vector<MouseInfo> others;
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
  // When a read first found the mouse gone (since plug-in; -1: never): the backend's own moment
  // of seeing the unplug. A test polling the backend's state sees it later by its own wake-up,
  // which a loaded machine delays (a fresh clone's ASan run: 152 ms).
  void noteGone(double sinceS) {
    double never = -1.0;
    goneSincePlugS_.compare_exchange_strong(never, sinceS);
  }
  double goneSincePlugS() const { return goneSincePlugS_.load(); }
  void sleepUntilSincePlug(double sinceS) const {
    const double waitS = sinceS - nowSincePlugS();
    if (waitS > 0) std::this_thread::sleep_for(std::chrono::duration<double>(waitS));
  }
  // The hidraw node now: a replug may give the mouse another.
  std::string hidPath() const {
    const bool replugged = nowSincePlugS() >= script_.replugAtS && !script_.replugPath.empty();
    return replugged ? script_.replugPath : script_.path;
  }
  // What enumeration lists: the others first (enumeration order is not the one to choose by),
  // then the mouse while it is plugged in.
  bool enumerate(const std::string& path, std::vector<MouseInfo>& out) const {
    out = script_.others;
    if (!present(nowSincePlugS())) return true;
    MouseInfo info;
    info.path = path;
    info.vendorId = static_cast<uint16_t>(script_.recording.vendorId);
    info.productId = static_cast<uint16_t>(script_.recording.productId);
    info.product = script_.recording.name;
    info.busPath = script_.busPath;
    out.push_back(info);
    return true;
  }
  // An open of `path` where the mouse is at `nodePath`: refused for permission (denyAccess),
  // not found (another node, or unplugged), else the mouse is plugged in from now on.
  bool open(const std::string& path, const std::string& nodePath, std::string& error, OpenFailure& why) {
    if (script_.denyAccess) {
      why = OpenFailure::kPermission;
      error = permissionFix(path);
      return false;
    }
    if (path != nodePath || !present(nowSincePlugS())) {
      why = OpenFailure::kNotFound;
      error = path + ": No such file or directory";
      return false;
    }
    why = OpenFailure::kNone;
    plugInOnce();
    return true;
  }

 private:
  FakeMouseScript script_;
  double plugS_ = 0.0;
  std::vector<Due> played_;
  std::atomic<double> goneSincePlugS_{-1.0};
};

// One reader's place in the timeline, and what both kinds of handle do alike: the stall,
// the unplug, the blocking read with its timeout.
class FakeReader {
 public:
  explicit FakeReader(std::shared_ptr<FakeTimeline> timeline)
      : timeline_(std::move(timeline)), openedS_(timeline_->nowSincePlugS()) {
    // A new reader sees only what comes after its open.
    while (next_ < timeline_->played().size() && timeline_->played()[next_].sincePlugS < openedS_) ++next_;
  }
  const FakeTimeline& timeline() const { return *timeline_; }

  // A blocking read: -1 with `onGone()` once unplugged, else the count `take(nowS)` hands over
  // (it queues what `due` gives and copies out), else 0 when timeoutMs has passed.
  template <class OnGone, class Take>
  int read(int timeoutMs, OnGone onGone, Take take) {
    const FakeMouseScript& s = timeline_->script();
    if (!stalled_ && timeline_->nowSincePlugS() >= s.stallAtS) {
      stalled_ = true;
      timeline_->sleepUntilSincePlug(s.stallAtS + s.stallForS);
    }
    const double deadlineS = timeline_->nowSincePlugS() + timeoutMs * 1e-3;
    for (;;) {
      const double nowS = timeline_->nowSincePlugS();
      // A handle opened before an unplug stays dead after the replug (a new node, a new open).
      if (nowS >= s.unplugAtS && openedS_ < s.unplugAtS) {
        timeline_->noteGone(nowS);
        onGone();
        return -1;
      }
      if (const int n = take(nowS); n > 0) return n;
      if (nowS >= deadlineS) return 0;
      double wakeS = std::min(deadlineS, s.unplugAtS);
      if (next_ < timeline_->played().size()) wakeS = std::min(wakeS, timeline_->played()[next_].sincePlugS);
      timeline_->sleepUntilSincePlug(std::max(wakeS, nowS + 1e-5));
    }
  }
  // Hands each report due by nowS that the kernel saw (the mouse plugged in) to `kernel`.
  template <class Kernel>
  void due(double nowS, Kernel kernel) {
    const auto& played = timeline_->played();
    while (next_ < played.size() && played[next_].sincePlugS <= nowS) {
      const auto& report = played[next_++];
      if (timeline_->present(report.sincePlugS)) kernel(report);
    }
  }

 private:
  std::shared_ptr<FakeTimeline> timeline_;
  double openedS_;
  size_t next_ = 0;
  bool stalled_ = false;
};

// --- hidapi -------------------------------------------------------------------------------

class FakeHidHandle : public HidHandle {
 public:
  explicit FakeHidHandle(std::shared_ptr<FakeTimeline> timeline) : reader_(std::move(timeline)) {}
  int readTimeout(uint8_t* buffer, size_t capacity, int timeoutMs) override {
    return reader_.read(
        timeoutMs, [&] { error_ = "hid_read_timeout: unexpected poll error (device disconnected)"; },
        [&](double nowS) {
          refill(nowS);
          if (queue_.empty()) return 0;
          std::vector<uint8_t> bytes = std::move(queue_.front());
          queue_.pop_front();
          const size_t n = std::min(bytes.size(), capacity);
          std::copy_n(bytes.begin(), n, buffer);
          return static_cast<int>(n);
        });
  }
  std::string lastError() override { return error_; }
  bool reportDescriptor(std::vector<uint8_t>& out, std::string&) override {
    out = reader_.timeline().script().recording.descriptor;
    return true;
  }
  int kernelDrops() const { return drops_; }

 private:
  void refill(double nowS) {
    const FakeMouseScript& s = reader_.timeline().script();
    reader_.due(nowS, [&](const FakeTimeline::Due& due) {
      if (queue_.size() + 1 >= s.kernelQueue) {  // hidraw: the slot after the head is the tail, dropped
        ++drops_;
        return;
      }
      ++count_;
      std::vector<uint8_t> bytes = due.bytes;
      if (s.shortReportEvery > 0 && count_ % s.shortReportEvery == 0) bytes.resize(3);
      queue_.push_back(std::move(bytes));
    });
  }

  FakeReader reader_;
  std::deque<std::vector<uint8_t>> queue_;
  std::string error_;
  int drops_ = 0;
  int count_ = 0;
};

class FakeHidApi : public HidApi {
 public:
  explicit FakeHidApi(FakeMouseScript script) : timeline(std::make_shared<FakeTimeline>(std::move(script))) {}
  bool enumerateMice(std::vector<MouseInfo>& out, std::string&) override {
    timeline->enumerate(timeline->hidPath(), out);
    for (MouseInfo& info : out) info.interfaceNumber = 0, info.usagePage = 1, info.usage = 2;
    return true;
  }
  std::unique_ptr<HidHandle> openPath(const std::string& path, std::string& error, OpenFailure& why) override {
    if (!timeline->open(path, timeline->hidPath(), error, why)) return nullptr;
    return std::make_unique<FakeHidHandle>(timeline);
  }
  std::shared_ptr<FakeTimeline> timeline;
};

// --- evdev --------------------------------------------------------------------------------

class FakeEvdevHandle : public EvdevHandle {
 public:
  explicit FakeEvdevHandle(std::shared_ptr<FakeTimeline> timeline) : reader_(std::move(timeline)) {}
  bool setMonotonicClock(std::string&) override {
    monotonic_ = true;
    return true;
  }
  bool grab(bool on, std::string&) override {
    grabbed = on;
    return true;
  }
  std::string name() override { return reader_.timeline().script().recording.name; }
  bool buttonsDown(uint32_t& buttons) override {  // the kernel's state: the latest report's
    buttons = buttons_;
    ++keyStateReads;
    return true;
  }
  int keyStateReads = 0;
  bool id(uint16_t& vendorId, uint16_t& productId) override {
    vendorId = static_cast<uint16_t>(reader_.timeline().script().recording.vendorId);
    productId = static_cast<uint16_t>(reader_.timeline().script().recording.productId);
    return true;
  }
  int read(EvdevEvent* out, int capacity, int timeoutMs, int* errnoOut) override {
    return reader_.read(
        timeoutMs, [&] { *errnoOut = ENODEV; },
        [&](double nowS) {
          refill(nowS);
          int n = 0;
          const int limit = std::min(capacity, reader_.timeline().script().maxEventsPerRead);
          while (n < limit && !queue_.empty()) {
            out[n++] = queue_.front();
            queue_.pop_front();
            if (out[n - 1].type == 0x00 && out[n - 1].code == 3) ++syncDropped_;
          }
          return n;
        });
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
    if (queue_.size() >= reader_.timeline().script().kernelQueue) {  // evdev: drop all, keep SYN_DROPPED + newest
      queue_.clear();
      queue_.push_back(EvdevEvent{event.timeS, 0x00, 3, 0});
      queue_.push_back(event);
    }
  }
  void refill(double nowS) {
    const FakeTimeline& timeline = reader_.timeline();
    reader_.due(nowS, [&](const FakeTimeline::Due& due) {
      const std::vector<uint8_t>& b = due.bytes;  // the Genius report 1: id, buttons, X, Y int16
      if (b.size() < 6 || b[0] != 1) return;
      const double t = monotonic_ ? stampS(timeline, due.sincePlugS) : 1.7e9 + due.sincePlugS;
      const int16_t dx = static_cast<int16_t>(b[2] | b[3] << 8), dy = static_cast<int16_t>(b[4] | b[5] << 8);
      if (dx != 0) push({t, 0x02, 0x00, dx});
      if (dy != 0) push({t, 0x02, 0x01, dy});
      for (int bit = 0; bit < 5; ++bit)
        if (((b[1] ^ buttons_) >> bit) & 1) push({t, 0x01, static_cast<uint16_t>(0x110 + bit), (b[1] >> bit) & 1});
      buttons_ = b[1];
      push({t, 0x00, 0x00, 0});
    });
  }

  FakeReader reader_;
  std::deque<EvdevEvent> queue_;
  uint8_t buttons_ = 0;
  bool monotonic_ = false;
  int syncDropped_ = 0;
};

class FakeEvdevApi : public EvdevApi {
 public:
  static constexpr const char* kNode = "/dev/input/event9";
  explicit FakeEvdevApi(FakeMouseScript script) : timeline(std::make_shared<FakeTimeline>(std::move(script))) {}
  // The node's HID device has the recording's descriptor (as sysfs shows it, MouseInfo::hidDescriptor).
  bool enumerateMice(std::vector<MouseInfo>& out, std::string&) override {
    timeline->enumerate(kNode, out);
    for (MouseInfo& info : out)
      if (info.path == kNode) info.hidDescriptor = timeline->script().recording.descriptor;
    return true;
  }
  std::unique_ptr<EvdevHandle> open(const std::string& path, std::string& error, OpenFailure& why) override {
    if (!timeline->open(path, kNode, error, why)) return nullptr;
    auto handle = std::make_unique<FakeEvdevHandle>(timeline);
    lastHandle = handle.get();
    return handle;
  }
  std::shared_ptr<FakeTimeline> timeline;
  FakeEvdevHandle* lastHandle = nullptr;  // for inspection while it lives
};

}  // namespace kf::test
