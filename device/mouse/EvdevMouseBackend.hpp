// EvdevMouseBackend (Linux): a mouse's input event node. Reports carry the kernel's own
// timestamps (EVIOCSCLOCKID to CLOCK_MONOTONIC), taken when the USB report came in, so the
// reader thread's wake-up jitter does not reach them; EVIOCGRAB on request keeps the desktop
// cursor still. A full kernel queue shows as SYN_DROPPED: the events up to the next
// SYN_REPORT are dropped, a loss is counted and the next report flagged; the buttons are then
// read back from the kernel (EVIOCGKEY), since a press or release may have been dropped.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "mouse/RealMouseBackend.hpp"

namespace kf {

class EvdevMouseBackend : public RealMouseBackend {
 public:
  // Enumerates, selects (MouseSelect's `which`), opens, sets the clock, grabs if asked, starts
  // the reader (scheduled as `thread` asks). Null with a message (and why) on failure.
  static std::unique_ptr<EvdevMouseBackend> open(std::shared_ptr<EvdevApi> api, const std::string& which, bool grab,
                                                 std::string& error, OpenFailure* why = nullptr,
                                                 const ThreadRequest& thread = {});
  ~EvdevMouseBackend() override { stop(); }
  std::string kindName() const override { return "evdev"; }
  // False when the kernel would not stamp with CLOCK_MONOTONIC: then arrival times are used.
  bool hasKernelTimestamps() const { return kernelTimestamps_; }

  // Where a delta is at its field's limit, so saturated: from the HID descriptor under the node
  // when there is one (MouseInfo::hidDescriptor), else guessed from 8- and 16-bit fields.
  struct AxisLimits {
    bool fromDescriptor = false;
    int64_t xLowest = 0, xHighest = 0, yLowest = 0, yHighest = 0;
    bool atLimit(bool isX, int32_t value) const;
  };
  const AxisLimits& axisLimits() const { return limits_; }  // the open's (the reader's own after)

 protected:
  int readSome(int timeoutMs) override;
  void closeHandle() override { handle_.reset(); }
  bool reopenHandle(std::string& error) override;

 private:
  EvdevMouseBackend(std::shared_ptr<EvdevApi> api, bool grab) : api_(std::move(api)), grab_(grab) {}
  bool openInfo(const MouseInfo& info, std::string& error, OpenFailure& why) override;
  void take(const EvdevEvent& event);
  void emitPacket(double kernelTimeS);  // the packet assembled so far, if it has anything

  std::shared_ptr<EvdevApi> api_;
  std::unique_ptr<EvdevHandle> handle_;
  bool grab_;
  std::atomic<bool> kernelTimestamps_{true};  // written by the reader at a re-open
  MouseInfo current_;                         // the reader thread's (and open's) own
  AxisLimits limits_;                         // current_'s
  // The packet being assembled (events up to SYN_REPORT; may span reads).
  int32_t dx_ = 0, dy_ = 0;
  uint32_t buttons_ = 0;
  bool packetHasData_ = false, packetSaturated_ = false;
  bool dropping_ = false, afterLoss_ = false;
};

}  // namespace kf
