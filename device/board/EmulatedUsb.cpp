#include "board/EmulatedUsb.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstring>

namespace kf::board {

namespace {
double steadyS() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
constexpr double kFrameS = 0.001;
constexpr double kHeldReplyLimitS = 10.0;  // a held ARM reply comes anyway: a broken test ends
}  // namespace

std::shared_ptr<EmulatedUsb> EmulatedUsb::create(std::string serial) {
  return std::shared_ptr<EmulatedUsb>(new EmulatedUsb(std::move(serial)));
}

EmulatedUsb::EmulatedUsb(std::string serial) : serial_(std::move(serial)), originS_(steadyS()), board_(0.0) {}

double EmulatedUsb::nowS() const { return steadyS() - originS_; }

// The host side: what libusb would be, on this bus.
class EmulatedPort : public usb::Port {
 public:
  explicit EmulatedPort(std::shared_ptr<EmulatedUsb> bus) : bus_(std::move(bus)) {}
  ~EmulatedPort() override {
    close(0.0);
    // What this port left in flight can never be delivered to it now.
    std::lock_guard<std::mutex> lock(bus_->mutex_);
    auto& pending = bus_->pending_;
    pending.erase(std::remove_if(pending.begin(), pending.end(),
                                 [this](const EmulatedUsb::Pending& p) { return p.owner == this; }),
                  pending.end());
  }

  usb::Result init() override { return usb::Result::kOk; }
  void exit() override {}

  usb::Result open(const usb::DeviceIds& ids) override {
    std::lock_guard<std::mutex> lock(bus_->mutex_);
    skipped_.clear();
    if (ids.vendorId != kVendorId || ids.productId != kProductId) return usb::Result::kNotFound;
    // The strangers come first on this bus; like LibusbPort, only their descriptors are read.
    int address = 1;
    for (const usb::InterfaceIdentity& stranger : bus_->strangers_) {
      const std::string mismatch = usb::interfaceMismatch(&stranger, ids.iface);
      if (mismatch.empty()) {
        ++bus_->strangerTouches_;  // taken for a board: it would be opened and claimed
        continue;
      }
      skipped_ +=
          (skipped_.empty() ? "" : "; ") + std::string("bus 1 device ") + std::to_string(address++) + ": " + mismatch;
    }
    const usb::InterfaceIdentity board{kInterfaceNumber, kInterfaceClass, kInterfaceSubclass, kInterfaceProtocol};
    if (!bus_->plugged_ || !usb::interfaceMismatch(&board, ids.iface).empty() ||
        (!ids.serial.empty() && ids.serial != bus_->serial_))
      return usb::Result::kNotFound;
    if (bus_->denyAccess_) return usb::Result::kAccess;
    if (generation_ == 0) ++bus_->openHandles_;
    generation_ = bus_->generation_;
    return usb::Result::kOk;
  }

  std::string skipped() const override { return skipped_; }
  std::string openSerial() const override {
    std::lock_guard<std::mutex> lock(bus_->mutex_);
    return bus_->serial_;
  }

  usb::InterfaceEndpoints openEndpoints() const override { return {kSetPointEndpoint, kStatusEndpoint}; }

  usb::Result claimInterface(int number) override {
    std::lock_guard<std::mutex> lock(bus_->mutex_);
    if (!alive()) return usb::Result::kNoDevice;
    if (number != kInterfaceNumber) return usb::Result::kNotFound;
    ++bus_->claims_;
    return usb::Result::kOk;
  }

  void releaseInterface(int) override {
    std::lock_guard<std::mutex> lock(bus_->mutex_);
    if (alive()) ++bus_->releases_;
  }

  void close(double callbackWaitS) override {
    std::unique_lock<std::mutex> lock(bus_->mutex_);
    if (generation_ == 0 || leaked_) return;
    if (ownInFlight(-1) > 0 && callbackWaitS > 0.0) {
      // As LibusbPort: cancel them and run events until they are back or the wait is over.
      ++bus_->closeWaits_;
      for (EmulatedUsb::Pending& pending : bus_->pending_)
        if (pending.owner == this) {
          pending.cancelled = true;
          pending.dueS = std::min(pending.dueS, bus_->nowS());
        }
      runCallbacks(lock, bus_->nowS() + callbackWaitS, INT_MAX, [this] { return ownInFlight(-1) == 0; });
    }
    if (const int inFlight = ownInFlight(-1)) {
      bus_->closesInFlight_ += inFlight;
      leaked_ = true;  // never freed: the handle stays open
      return;
    }
    --bus_->openHandles_;
    generation_ = 0;
  }

  usb::Result control(uint8_t requestType, uint8_t request, uint16_t value, uint16_t index, uint8_t* data,
                      uint16_t length, unsigned, int* transferred) override {
    std::unique_lock<std::mutex> lock(bus_->mutex_);
    if (!alive()) return usb::Result::kNoDevice;
    if (ownInFlight(-1) > 0 && std::this_thread::get_id() != eventThread_) ++bus_->eventsOffThread_;
    if (index != kInterfaceNumber) return usb::Result::kPipe;
    if (request == static_cast<uint8_t>(Request::kArm) && bus_->holdArm_) {
      ++bus_->armsHeld_;
      bus_->changed_.notify_all();
      runCallbacks(lock, bus_->nowS() + kHeldReplyLimitS, INT_MAX, [this] { return !bus_->holdArm_; });
      --bus_->armsHeld_;
      if (!alive()) return usb::Result::kNoDevice;
    }
    const usb::Result result =
        bus_->board_.control(requestType, request, value, data, length, transferred, bus_->nowS());
    runCallbacks(lock, bus_->nowS(), INT_MAX, [] { return false; });  // those due by the reply
    return result;
  }

  usb::Result clearHalt(uint8_t endpoint) override {
    std::lock_guard<std::mutex> lock(bus_->mutex_);
    if (!alive()) return usb::Result::kNoDevice;
    if (ownInFlight(endpoint) > 0) ++bus_->haltsInFlight_;
    if (endpoint == kSetPointEndpoint) bus_->outHalted_ = false;
    ++bus_->clearHalts_;
    return usb::Result::kOk;
  }

  usb::Result submit(usb::Transfer& transfer) override {
    std::lock_guard<std::mutex> lock(bus_->mutex_);
    if (!alive()) return usb::Result::kNoDevice;
    for (const EmulatedUsb::Pending& p : bus_->pending_)
      if (p.transfer == &transfer) {
        ++bus_->resubmitsInFlight_;  // libusb: LIBUSB_ERROR_BUSY, and the host lost track of it
        return usb::Result::kBusy;
      }
    const double nowS = bus_->nowS();
    EmulatedUsb::Pending pending{this, &transfer, nowS, generation_, false, false, false, false};
    if (transfer.endpoint == kSetPointEndpoint) {
      if (bus_->failOut_) {
        pending.failed = true;  // done at once
      } else if (bus_->timeOutOut_ > 0) {
        --bus_->timeOutOut_;
        pending.timeOut = true;
        pending.dueS = nowS + transfer.timeoutMs * 1e-3;
      } else {
        // One transfer per 1 ms frame on an interrupt endpoint.
        bus_->nextOutS_ = std::max(nowS, bus_->nextOutS_ + kFrameS);
        pending.dueS = bus_->nextOutS_;
        if (bus_->partialOut_ > 0) {
          --bus_->partialOut_;
          pending.partial = true;
        }
      }
    } else if (transfer.endpoint == kStatusEndpoint) {
      bus_->nextInS_ = std::max(nowS, bus_->nextInS_ + kFrameS);
      pending.dueS = bus_->nextInS_;
      if (bus_->partialIn_ > 0) {
        --bus_->partialIn_;
        pending.partial = true;
      }
    } else {
      return usb::Result::kInvalid;
    }
    bus_->pending_.push_back(pending);
    bus_->changed_.notify_all();
    return usb::Result::kOk;
  }

  usb::Result cancel(usb::Transfer& transfer) override {
    std::lock_guard<std::mutex> lock(bus_->mutex_);
    for (EmulatedUsb::Pending& pending : bus_->pending_)
      if (pending.transfer == &transfer) {
        pending.cancelled = true;
        pending.dueS = std::min(pending.dueS, bus_->nowS());
        bus_->changed_.notify_all();
        return usb::Result::kOk;
      }
    return usb::Result::kNotFound;
  }

  usb::Result handleEvents(int timeoutMs) override {
    const double deadlineS = bus_->nowS() + timeoutMs * 1e-3;
    std::unique_lock<std::mutex> lock(bus_->mutex_);
    eventThread_ = std::this_thread::get_id();
    runCallbacks(lock, deadlineS, 1, [] { return false; });
    return usb::Result::kOk;
  }

 private:
  // Under `lock`, released around each callback (they submit again): runs this port's
  // callbacks as they come due, the earliest first, until `stop()` holds, `maxCallbacks` ran
  // or the bus clock passes deadlineS.
  template <class Stop>
  void runCallbacks(std::unique_lock<std::mutex>& lock, double deadlineS, int maxCallbacks, Stop stop) {
    int ran = 0;
    while (ran < maxCallbacks && !stop()) {
      const double nowS = bus_->nowS();
      bus_->board_.advance(nowS);
      // The earliest transfer that is done by now (cancelled and dead ones are done at once).
      auto next = bus_->pending_.end();
      double nextDueS = 0.0;
      double earliestS = deadlineS;
      for (auto it = bus_->pending_.begin(); it != bus_->pending_.end(); ++it) {
        if (it->owner != this) continue;  // another host's transfer: its own thread runs it
        const bool delayed =
            bus_->callbackDelayEndpoint_ == 0 || bus_->callbackDelayEndpoint_ == it->transfer->endpoint;
        const double dueS = it->dueS + (delayed ? bus_->callbackDelayS_ : 0.0);
        if (dueS <= nowS && (next == bus_->pending_.end() || dueS < nextDueS)) {
          next = it;
          nextDueS = dueS;
        }
        earliestS = std::min(earliestS, dueS);
      }
      if (next != bus_->pending_.end()) {
        EmulatedUsb::Pending done = *next;
        bus_->pending_.erase(next);
        complete(done, nowS);
        lock.unlock();
        if (done.transfer->callback != nullptr) done.transfer->callback(*done.transfer);
        lock.lock();
        ++ran;
        continue;
      }
      if (nowS >= deadlineS) return;
      bus_->changed_.wait_for(lock, std::chrono::duration<double>(std::max(0.0, earliestS - nowS)));
    }
  }

  bool alive() const { return generation_ != 0 && generation_ == bus_->generation_ && bus_->plugged_; }

  // Under the lock: this port's transfers whose callbacks have not run (endpoint -1: any).
  int ownInFlight(int endpoint) const {
    int count = 0;
    for (const EmulatedUsb::Pending& p : bus_->pending_)
      if (p.owner == this && (endpoint < 0 || p.transfer->endpoint == endpoint)) ++count;
    return count;
  }

  // Under the lock: what the transfer did.
  void complete(const EmulatedUsb::Pending& pending, double nowS) {
    usb::Transfer& transfer = *pending.transfer;
    transfer.actualLength = 0;
    if (pending.generation != bus_->generation_ || !bus_->plugged_) {
      transfer.status = usb::TransferStatus::kNoDevice;
    } else if (pending.cancelled) {
      transfer.status = usb::TransferStatus::kCancelled;
    } else if (pending.timeOut) {
      transfer.status = usb::TransferStatus::kTimedOut;
    } else if (pending.failed) {
      transfer.status = usb::TransferStatus::kError;
    } else if (transfer.endpoint == kSetPointEndpoint) {
      if (bus_->outHalted_) {
        transfer.status = usb::TransferStatus::kStall;
        return;
      }
      transfer.status = usb::TransferStatus::kCompleted;
      transfer.actualLength = pending.partial ? transfer.length / 2 : transfer.length;
      bus_->board_.receiveSetPoint(transfer.buffer, static_cast<size_t>(transfer.actualLength), pending.dueS);
    } else {
      uint8_t frame[kStatusSize];
      encodeStatus(bus_->board_.status(nowS), frame);
      const int size = std::min<int>(transfer.length, kStatusSize);
      transfer.actualLength = pending.partial ? size / 2 : size;
      std::memcpy(transfer.buffer, frame, static_cast<size_t>(transfer.actualLength));
      transfer.status = usb::TransferStatus::kCompleted;
    }
  }

  std::shared_ptr<EmulatedUsb> bus_;
  int generation_ = 0;           // of the plug-in it was opened on; 0: not open
  bool leaked_ = false;          // closed with a transfer in flight: the handle stays open
  std::thread::id eventThread_;  // the last to call handleEvents
  std::string skipped_;
};

std::unique_ptr<usb::Port> EmulatedUsb::makePort() { return std::make_unique<EmulatedPort>(shared_from_this()); }

void EmulatedUsb::unplug() {
  std::lock_guard<std::mutex> lock(mutex_);
  plugged_ = false;
  const double now = nowS();
  board_.powerLoss(now);
  for (Pending& pending : pending_) pending.dueS = std::min(pending.dueS, now);  // they end: no device
  changed_.notify_all();
}

void EmulatedUsb::replug(const std::string& serial) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (plugged_) return;
  plugged_ = true;
  if (!serial.empty()) serial_ = serial;
  ++generation_;  // handles of the old plug-in stay dead
  outHalted_ = false;
  board_.powerOn(nowS());
  changed_.notify_all();
}

void EmulatedUsb::busReset() {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.usbReset(nowS(), "usb reset");
}
void EmulatedUsb::suspend() {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.usbReset(nowS(), "suspend");
}
void EmulatedUsb::overCurrent(bool persists) {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.overCurrent(nowS(), persists);
}
void EmulatedUsb::setOverCurrent(bool present) {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.setOverCurrent(present);
}
void EmulatedUsb::setProtocolMajor(uint8_t major) {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.setProtocolMajor(major);
}
void EmulatedUsb::setProtocolMinor0() {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.setProtocolMinor0();
}
void EmulatedUsb::delayCallbacks(double seconds, uint8_t endpoint) {
  std::lock_guard<std::mutex> lock(mutex_);
  callbackDelayS_ = seconds;
  callbackDelayEndpoint_ = endpoint;
  changed_.notify_all();
}
void EmulatedUsb::addStranger(usb::InterfaceIdentity iface) {
  std::lock_guard<std::mutex> lock(mutex_);
  strangers_.push_back(iface);
}
int EmulatedUsb::strangerTouches() {
  std::lock_guard<std::mutex> lock(mutex_);
  return strangerTouches_;
}
int EmulatedUsb::closesInFlight() {
  std::lock_guard<std::mutex> lock(mutex_);
  return closesInFlight_;
}
int EmulatedUsb::resubmitsInFlight() {
  std::lock_guard<std::mutex> lock(mutex_);
  return resubmitsInFlight_;
}
int EmulatedUsb::haltsInFlight() {
  std::lock_guard<std::mutex> lock(mutex_);
  return haltsInFlight_;
}
int EmulatedUsb::eventsOffThread() {
  std::lock_guard<std::mutex> lock(mutex_);
  return eventsOffThread_;
}
int EmulatedUsb::closeWaits() {
  std::lock_guard<std::mutex> lock(mutex_);
  return closeWaits_;
}
void EmulatedUsb::holdArmReply(bool hold) {
  std::lock_guard<std::mutex> lock(mutex_);
  holdArm_ = hold;
  changed_.notify_all();
}
int EmulatedUsb::armsHeld() {
  std::lock_guard<std::mutex> lock(mutex_);
  return armsHeld_;
}

void EmulatedUsb::setDenyAccess(bool deny) {
  std::lock_guard<std::mutex> lock(mutex_);
  denyAccess_ = deny;
}
void EmulatedUsb::setRefuseArm(bool refuse) {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.setRefuseArm(refuse);
}
void EmulatedUsb::timeOutNextOut(int count) {
  std::lock_guard<std::mutex> lock(mutex_);
  timeOutOut_ += count;
}
void EmulatedUsb::partialNextOut(int count) {
  std::lock_guard<std::mutex> lock(mutex_);
  partialOut_ += count;
}
void EmulatedUsb::failOut(bool fail) {
  std::lock_guard<std::mutex> lock(mutex_);
  failOut_ = fail;
}
void EmulatedUsb::partialNextIn(int count) {
  std::lock_guard<std::mutex> lock(mutex_);
  partialIn_ += count;
}
void EmulatedUsb::stallOut() {
  std::lock_guard<std::mutex> lock(mutex_);
  outHalted_ = true;
}

std::vector<BoardEmulator::Change> EmulatedUsb::timeline() {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.advance(nowS());
  return board_.timeline();
}
Status EmulatedUsb::status() {
  std::lock_guard<std::mutex> lock(mutex_);
  return board_.status(nowS());
}
uint64_t EmulatedUsb::validFrames() {
  std::lock_guard<std::mutex> lock(mutex_);
  return board_.validFrames();
}
uint64_t EmulatedUsb::rejectedFrames() {
  std::lock_guard<std::mutex> lock(mutex_);
  return board_.rejectedFrames();
}
BoardState EmulatedUsb::state() {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.advance(nowS());
  return board_.state();
}
uint16_t EmulatedUsb::drive() {
  std::lock_guard<std::mutex> lock(mutex_);
  board_.advance(nowS());
  return board_.drive();
}
int EmulatedUsb::interfaceClaims() {
  std::lock_guard<std::mutex> lock(mutex_);
  return claims_;
}
int EmulatedUsb::interfaceReleases() {
  std::lock_guard<std::mutex> lock(mutex_);
  return releases_;
}
int EmulatedUsb::clearHalts() {
  std::lock_guard<std::mutex> lock(mutex_);
  return clearHalts_;
}
bool EmulatedUsb::isOpen() {
  std::lock_guard<std::mutex> lock(mutex_);
  return openHandles_ > 0;
}

}  // namespace kf::board
