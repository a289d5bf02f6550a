// StallingIo: the real hidapi and evdev (realHidApi, realEvdevApi) with one addition a test
// needs: while stall() is on, the backend's reader thread is held at its next read, as a reader
// descheduled for that long would be, so that the kernel's own queues fill and drop.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

#include "mouse/MouseIo.hpp"

namespace kf::guest {

struct Stall {
  std::atomic<bool> on{false};
  std::atomic<int> held{0};  // readers held now
  void waitWhileOn() {
    if (!on.load()) return;
    ++held;
    while (on.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    --held;
  }
};

class StallingHidHandle : public HidHandle {
 public:
  StallingHidHandle(std::unique_ptr<HidHandle> real, std::shared_ptr<Stall> stall)
      : real_(std::move(real)), stall_(std::move(stall)) {}
  int readTimeout(uint8_t* buffer, size_t capacity, int timeoutMs) override {
    stall_->waitWhileOn();
    return real_->readTimeout(buffer, capacity, timeoutMs);
  }
  std::string lastError() override { return real_->lastError(); }
  bool reportDescriptor(std::vector<uint8_t>& out, std::string& error) override {
    return real_->reportDescriptor(out, error);
  }

 private:
  std::unique_ptr<HidHandle> real_;
  std::shared_ptr<Stall> stall_;
};

class StallingHidApi : public HidApi {
 public:
  explicit StallingHidApi(std::shared_ptr<Stall> stall) : stall_(std::move(stall)) {}
  bool enumerateMice(std::vector<MouseInfo>& out, std::string& error) override {
    return real_->enumerateMice(out, error);
  }
  std::unique_ptr<HidHandle> openPath(const std::string& path, std::string& error, OpenFailure& why) override {
    auto handle = real_->openPath(path, error, why);
    return handle ? std::make_unique<StallingHidHandle>(std::move(handle), stall_) : nullptr;
  }

 private:
  std::shared_ptr<HidApi> real_ = realHidApi();
  std::shared_ptr<Stall> stall_;
};

class StallingEvdevHandle : public EvdevHandle {
 public:
  StallingEvdevHandle(std::unique_ptr<EvdevHandle> real, std::shared_ptr<Stall> stall)
      : real_(std::move(real)), stall_(std::move(stall)) {}
  bool setMonotonicClock(std::string& error) override { return real_->setMonotonicClock(error); }
  bool grab(bool on, std::string& error) override { return real_->grab(on, error); }
  std::string name() override { return real_->name(); }
  bool id(uint16_t& vendorId, uint16_t& productId) override { return real_->id(vendorId, productId); }
  bool buttonsDown(uint32_t& buttons) override { return real_->buttonsDown(buttons); }
  int read(EvdevEvent* out, int capacity, int timeoutMs, int* errnoOut) override {
    stall_->waitWhileOn();
    return real_->read(out, capacity, timeoutMs, errnoOut);
  }

 private:
  std::unique_ptr<EvdevHandle> real_;
  std::shared_ptr<Stall> stall_;
};

class StallingEvdevApi : public EvdevApi {
 public:
  explicit StallingEvdevApi(std::shared_ptr<Stall> stall) : stall_(std::move(stall)) {}
  bool enumerateMice(std::vector<MouseInfo>& out, std::string& error) override {
    return real_->enumerateMice(out, error);
  }
  std::unique_ptr<EvdevHandle> open(const std::string& path, std::string& error, OpenFailure& why) override {
    auto handle = real_->open(path, error, why);
    return handle ? std::make_unique<StallingEvdevHandle>(std::move(handle), stall_) : nullptr;
  }

 private:
  std::shared_ptr<EvdevApi> real_ = realEvdevApi();
  std::shared_ptr<Stall> stall_;
};

}  // namespace kf::guest
