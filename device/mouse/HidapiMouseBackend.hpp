// HidapiMouseBackend: any USB/Bluetooth HID mouse through hidapi. Reports are decoded through
// the device's own report descriptor (never the boot layout) and stamped on arrival with the
// monotonic clock. The kernel keeps at most 63 reports per hidraw reader and drops new ones
// when full, so a read that finds a full queue counts a loss and flags the next report. hidraw
// says nothing when it drops: a full queue may also be 63 reports that all fit, so the count
// is an estimate (kfStatus says so).
#pragma once

#include <memory>
#include <string>

#include "hid/HidMouseDecoder.hpp"
#include "mouse/RealMouseBackend.hpp"

namespace kf {

class HidapiMouseBackend : public RealMouseBackend {
 public:
  // linux/drivers/hid/hidraw.c keeps a ring of HIDRAW_BUFFER_SIZE (64) slots per reader and
  // drops a report when the slot after the head is the tail: one slot stays empty, 63 hold.
  static constexpr int kKernelQueueReports = 63;

  // Enumerates, selects (MouseSelect's `which`), opens, reads the descriptor, starts the
  // reader (scheduled as `thread` asks). Null with a message (and why) on failure.
  static std::unique_ptr<HidapiMouseBackend> open(std::shared_ptr<HidApi> api, const std::string& which,
                                                  std::string& error, OpenFailure* why = nullptr,
                                                  const ThreadRequest& thread = {});
  ~HidapiMouseBackend() override { stop(); }
  std::string kindName() const override { return "hidapi"; }
  bool lossesEstimated() const override { return true; }

 protected:
  int readSome(int timeoutMs) override;
  void closeHandle() override { handle_.reset(); }
  bool reopenHandle(std::string& error) override;

 private:
  explicit HidapiMouseBackend(std::shared_ptr<HidApi> api) : api_(std::move(api)) {}
  bool openInfo(const MouseInfo& info, std::string& error, OpenFailure& why) override;
  void take(const uint8_t* bytes, int size, double arrivalS);

  std::shared_ptr<HidApi> api_;
  std::unique_ptr<HidHandle> handle_;
  HidMouseDecoder decoder_;
  uint32_t buttons_ = 0;  // as the last report that carried them left them
  bool afterLoss_ = false;
  MouseInfo current_;  // the reader thread's (and open's) own
};

}  // namespace kf
