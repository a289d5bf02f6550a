#include "CountingPort.hpp"

#include <algorithm>

namespace kf::guest {

namespace {
// The ports whose transfers are in flight, so that a callback finds its port (the driver keeps
// transfer.user for itself). One test at a time: a plain mutex is enough.
std::mutex gRegistryMutex;
std::map<usb::Transfer*, CountingPort*> gPortOf;
}  // namespace

CountingPort::CountingPort(std::unique_ptr<usb::Port> inner) : inner_(std::move(inner)) {}

CountingPort::~CountingPort() {
  inner_.reset();  // LibusbPort's own close runs first, while this port still counts
  std::lock_guard<std::mutex> lock(gRegistryMutex);
  for (auto it = gPortOf.begin(); it != gPortOf.end();) it = it->second == this ? gPortOf.erase(it) : std::next(it);
}

CountingPort::Counts CountingPort::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return *shared_;
}

std::vector<CountingPort::SetPointOutcome> CountingPort::setPoints() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return setPoints_;
}

void CountingPort::close(double callbackWaitS) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++shared_->closes;
    shared_->inFlightAtClose = std::max(shared_->inFlightAtClose, inFlight_);
  }
  inner_->close(callbackWaitS);
}

usb::Result CountingPort::submit(usb::Transfer& transfer) {
  {
    std::lock_guard<std::mutex> lock(gRegistryMutex);
    gPortOf[&transfer] = this;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (transfer.callback != &CountingPort::onDone) {
      callbacks_[&transfer] = transfer.callback;
      transfer.callback = &CountingPort::onDone;
    }
    ++inFlight_;  // before the submit: its callback may run before submit returns
  }
  const usb::Result result = inner_->submit(transfer);
  std::lock_guard<std::mutex> lock(mutex_);
  if (result == usb::Result::kOk)
    ++shared_->submitted;
  else
    --inFlight_;
  return result;
}

void CountingPort::onDone(usb::Transfer& transfer) {
  CountingPort* self = nullptr;
  {
    std::lock_guard<std::mutex> lock(gRegistryMutex);
    self = gPortOf[&transfer];
  }
  void (*original)(usb::Transfer&) = nullptr;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    --self->inFlight_;
    ++self->shared_->calledBack;
    if (transfer.status == usb::TransferStatus::kCancelled) ++self->shared_->cancelled;
    if (transfer.status == usb::TransferStatus::kNoDevice) ++self->shared_->noDevice;
    if (!(transfer.endpoint & 0x80) && transfer.length >= 4)
      self->setPoints_.push_back({static_cast<uint16_t>(transfer.buffer[2] | (transfer.buffer[3] << 8)),
                                  transfer.status, transfer.actualLength});
    original = self->callbacks_[&transfer];
  }
  if (original != nullptr) original(transfer);
}

}  // namespace kf::guest
