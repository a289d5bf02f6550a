// CountingPort: a usb::Port around the real LibusbPort that watches libusb's transfer life cycle
// from outside the driver: every transfer submitted, every callback come back (and with which
// status), and how many were still in flight when the driver closed the handle (after which the
// port frees its transfers). The driver's rule (PROTOCOL.md 8.6, 8.7) is that this is always 0.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "board/UsbPort.hpp"

namespace kf::guest {

class CountingPort : public usb::Port {
 public:
  struct Counts {
    int submitted = 0;
    int calledBack = 0;
    int cancelled = 0;  // callbacks with kCancelled
    int noDevice = 0;   // callbacks with kNoDevice
    int closes = 0;
    int inFlightAtClose = 0;  // the most in flight at any close()
  };

  // What became of each set-point the driver sent: its sequence (read from the transfer's
  // bytes) and how its transfer ended.
  struct SetPointOutcome {
    uint16_t sequence;
    usb::TransferStatus status;
    int actualLength;
  };

  explicit CountingPort(std::unique_ptr<usb::Port> inner);
  ~CountingPort() override;
  // The counts so far, readable after the driver is gone (they outlive the port).
  std::shared_ptr<const Counts> counts() const { return shared_; }
  Counts snapshot() const;
  std::vector<SetPointOutcome> setPoints() const;

  usb::Result init() override { return inner_->init(); }
  void exit() override { inner_->exit(); }
  usb::Result open(const usb::DeviceIds& ids) override { return inner_->open(ids); }
  std::string skipped() const override { return inner_->skipped(); }
  std::string openSerial() const override { return inner_->openSerial(); }
  usb::InterfaceEndpoints openEndpoints() const override { return inner_->openEndpoints(); }
  usb::Result claimInterface(int number) override { return inner_->claimInterface(number); }
  void releaseInterface(int number) override { inner_->releaseInterface(number); }
  void close(double callbackWaitS) override;
  usb::Result control(uint8_t requestType, uint8_t request, uint16_t value, uint16_t index, uint8_t* data,
                      uint16_t length, unsigned timeoutMs, int* transferred) override {
    return inner_->control(requestType, request, value, index, data, length, timeoutMs, transferred);
  }
  usb::Result clearHalt(uint8_t endpoint) override { return inner_->clearHalt(endpoint); }
  usb::Result submit(usb::Transfer& transfer) override;
  usb::Result cancel(usb::Transfer& transfer) override { return inner_->cancel(transfer); }
  usb::Result handleEvents(int timeoutMs) override { return inner_->handleEvents(timeoutMs); }

 private:
  static void onDone(usb::Transfer& transfer);

  std::unique_ptr<usb::Port> inner_;
  mutable std::mutex mutex_;
  std::shared_ptr<Counts> shared_ = std::make_shared<Counts>();
  int inFlight_ = 0;
  std::map<usb::Transfer*, void (*)(usb::Transfer&)> callbacks_;  // the driver's own, per transfer
  std::vector<SetPointOutcome> setPoints_;
};

}  // namespace kf::guest
