#include "board/UsbBoardBackend.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace kf {

namespace {

constexpr uint8_t kVendorOut = 0x41;  // vendor, interface, host to device
constexpr uint8_t kVendorIn = 0xC1;
constexpr unsigned kControlTimeoutMs = 200;

double steadyS() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

std::string idsText(const usb::DeviceIds& ids) {
  char text[80];
  std::snprintf(text, sizeof text, "USB %04x:%04x", ids.vendorId, ids.productId);
  return ids.serial.empty() ? std::string(text) : std::string(text) + " serial " + ids.serial;
}

}  // namespace

UsbBoardBackend::UsbBoardBackend(std::unique_ptr<usb::Port> port, BoardOptions options)
    : port_(std::move(port)), options_(options), ids_(options.ids) {
  for (usb::Transfer& transfer : outTransfers_) transfer.length = board::kSetPointSize;
  zeroTransfer_.length = board::kSetPointSize;
  statusTransfer_.length = board::kStatusSize;
  useEndpoints({board::kSetPointEndpoint, board::kStatusEndpoint});
  for (usb::Transfer* transfer :
       {&outTransfers_[0], &outTransfers_[1], &outTransfers_[2], &outTransfers_[3], &statusTransfer_, &zeroTransfer_}) {
    transfer->timeoutMs = options_.transferTimeoutMs;
    transfer->callback = &UsbBoardBackend::onTransfer;
    transfer->user = this;
  }
}

UsbBoardBackend::~UsbBoardBackend() { close(); }

void UsbBoardBackend::useEndpoints(const usb::InterfaceEndpoints& endpoints) {
  endpoints_ = endpoints;
  for (usb::Transfer& transfer : outTransfers_) transfer.endpoint = endpoints.out;
  zeroTransfer_.endpoint = endpoints.out;
  statusTransfer_.endpoint = endpoints.in;
}

void UsbBoardBackend::setError(const std::string& error) {
  std::lock_guard<PiMutex> lock(telemetryMutex_);
  telemetry_.lastError = error;
}

bool UsbBoardBackend::connectLocked(std::string& error) {
  if (leaked_) {
    // Its handle is still open with the interface claimed: nothing in this process can use it.
    error = usb::describe(usb::Result::kLeaked);
    return false;
  }
  usb::Result result = port_->open(ids_);
  if (result == usb::Result::kNotFound) {
    error = "no friction board found (" + idsText(ids_) + "); is it plugged in?";
    const std::string skipped = port_->skipped();
    if (!skipped.empty()) error += " Left alone, not a board: " + skipped;
    return false;
  }
  if (result != usb::Result::kOk) {
    error = "cannot open the friction board (" + idsText(ids_) + "): " + usb::describe(result);
    return false;
  }
  // No transfer is in flight here (before the event thread, or after every callback of the
  // handle before): the transfers take this board's endpoints.
  useEndpoints(port_->openEndpoints());
  result = port_->claimInterface(board::kInterfaceNumber);
  if (result != usb::Result::kOk) {
    error = std::string("cannot claim the friction board's interface: ") + usb::describe(result);
    port_->close(0.0);
    return false;
  }
  uint8_t reply[board::kVersionSize] = {};  // a 2.0 board answers 8 bytes of it
  int moved = 0;
  result = control(kVendorIn, static_cast<uint8_t>(board::Request::kGetVersion), 0, reply, board::kVersionSize, &moved);
  board::VersionReply version;
  if (result != usb::Result::kOk || !board::decodeVersion(reply, static_cast<size_t>(moved), version)) {
    error = std::string("the board did not answer GET_VERSION: ") + usb::describe(result);
  } else if (version.protocolMajor != board::kProtocolMajor) {
    error = "the board speaks protocol " + std::to_string(version.protocolMajor) + "." +
            std::to_string(version.protocolMinor) + ", this host " + std::to_string(board::kProtocolMajor) +
            ".x: update the board's firmware (or KineticFriction) so that both speak " +
            std::to_string(board::kProtocolMajor) + ".x";
  } else {
    // As many levels per frame as both can: the largest divisor of the device's count the board
    // plays (a 2.0 board: one, the mean of the device's levels of that millisecond).
    const int wanted = std::clamp(options_.subSetPoints, 1, board::kMaxSubSetPoints);
    subSetPoints_ = std::min<int>(wanted, version.maxSubSetPoints);
    while (wanted % subSetPoints_ != 0) --subSetPoints_;
    levelsPerSubSetPoint_ = wanted / subSetPoints_;
    const int frameSize =
        static_cast<int>(subSetPoints_ > 1 ? board::multiSetPointSize(subSetPoints_) : board::kSetPointSize);
    for (usb::Transfer& transfer : outTransfers_) transfer.length = frameSize;
    {
      std::lock_guard<PiMutex> lock(telemetryMutex_);
      telemetry_.version = version;
      telemetry_.subSetPoints = subSetPoints_;
      telemetry_.serial = port_->openSerial();
      telemetry_.haveStatus = false;
    }
    // The enumeration's reset (and any fault left from before) is read and cleared here, so
    // the status frames show only what happens from now on.
    board::ClearReply cleared;
    if (clearErrorsLocked(cleared, error)) return true;
  }
  port_->releaseInterface(board::kInterfaceNumber);
  port_->close(0.0);
  return false;
}

bool UsbBoardBackend::clearErrorsLocked(board::ClearReply& reply, std::string& error) {
  uint8_t data[board::kClearReplySize] = {};
  int moved = 0;
  const usb::Result result =
      control(kVendorIn, static_cast<uint8_t>(board::Request::kClearErrors), 0, data, board::kClearReplySize, &moved);
  if (result != usb::Result::kOk || !board::decodeClearReply(data, static_cast<size_t>(moved), reply)) {
    error = std::string("the board did not answer CLEAR_ERRORS: ") + usb::describe(result);
    return false;
  }
  std::lock_guard<PiMutex> lock(telemetryMutex_);
  telemetry_.lastClear = reply;
  if (reply.before & board::kErrUsbReset) ++telemetry_.boardResets;
  return true;
}

bool UsbBoardBackend::open(std::string& error) {
  if (opened_.load()) return true;
  std::lock_guard<std::mutex> lock(portMutex_);
  const usb::Result init = port_->init();
  if (init != usb::Result::kOk) {
    error = std::string("libusb could not start: ") + usb::describe(init);
    return false;
  }
  ids_ = options_.ids;
  if (!connectLocked(error)) {
    port_->exit();
    return false;
  }
  ids_.serial = port_->openSerial();  // from now on this board only (a board without a serial: any)
  armed_.store(false);
  connected_.store(true);
  stopping_.store(false);
  opened_.store(true);
  {
    std::lock_guard<std::mutex> wakeLock(wakeMutex_);
    eventThreadServes_ = true;
  }
  thread_ = std::thread([this] { run(); });
  return true;
}

void UsbBoardBackend::close() {
  if (!opened_.exchange(false)) return;
  {
    // Under the lock: else the store and notify could fall between the reconnect wait's check
    // of stopping_ and its sleep, which then lasts a whole reopenPeriodS. (No test here shows
    // it: the window is a few instructions wide.)
    std::lock_guard<std::mutex> wakeLock(wakeMutex_);
    stopping_.store(true);
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

usb::Result UsbBoardBackend::control(uint8_t requestType, uint8_t request, uint16_t value, uint8_t* data,
                                     uint16_t length, int* moved) {
  std::unique_lock<std::mutex> lock(wakeMutex_);
  if (!eventThreadServes_ || eventThreadId_.load() == std::this_thread::get_id()) {
    lock.unlock();
    return port_->control(requestType, request, value, board::kInterfaceNumber, data, length, kControlTimeoutMs, moved);
  }
  ControlRequest posted{requestType, request, value, data, length};
  controlDone_.wait(lock, [this] { return controlRequest_ == nullptr || !eventThreadServes_; });
  if (!eventThreadServes_) return usb::Result::kNoDevice;  // closed meanwhile
  controlRequest_ = &posted;
  wake_.notify_all();  // a reconnect wait
  controlDone_.wait(lock, [&posted] { return posted.done; });
  if (moved != nullptr) *moved = posted.moved;
  return posted.result;
}

void UsbBoardBackend::serveControl() {
  ControlRequest* request = nullptr;
  {
    std::lock_guard<std::mutex> lock(wakeMutex_);
    request = controlRequest_;
  }
  if (request == nullptr) return;
  int moved = 0;
  const usb::Result result =
      port_->control(request->requestType, request->request, request->value, board::kInterfaceNumber, request->data,
                     request->length, kControlTimeoutMs, &moved);
  {
    std::lock_guard<std::mutex> lock(wakeMutex_);
    request->moved = moved;
    request->result = result;
    request->done = true;
    controlRequest_ = nullptr;
  }
  controlDone_.notify_all();
}

bool UsbBoardBackend::arm(std::string& error) {
  std::lock_guard<std::mutex> lock(commandMutex_);
  if (!connected_.load()) {
    error = "the friction board is not connected";
    return false;
  }
  {
    // ARM while armed changes nothing, on the board (PROTOCOL.md 5) and here: no restart.
    std::lock_guard<PiMutex> telemetryLock(telemetryMutex_);
    if (armed_.load() && telemetry_.haveStatus && telemetry_.status.state == board::BoardState::kArmed) return true;
  }
  board::ClearReply cleared;
  if (!clearErrorsLocked(cleared, error)) return false;
  if (cleared.remaining & board::kErrOverCurrent) {
    error =
        "the board is in fault: over current, and it persists (a shorted or miswired coil?); switch the coil "
        "supply off, fix it, then arm again";
    return false;
  }
  if (cleared.remaining & board::kErrOverTemperature) {
    error = "the board is too hot (over temperature); let it cool, then arm again";
    return false;
  }
  if (cleared.remaining & board::kErrSupply) {
    error = "the board's coil supply is off or too low; switch it on, then arm again";
    return false;
  }
  // From off: set-points carry 0 until the device has restarted its slew limiter.
  latestDrive_.store(kRestartPending, std::memory_order_relaxed);
  const usb::Result result =
      control(kVendorOut, static_cast<uint8_t>(board::Request::kArm), board::kArmKey, nullptr, 0, nullptr);
  if (result == usb::Result::kPipe) {
    error = "the board refused to arm (a fault, over temperature or no coil supply: see its error flags)";
    return false;
  }
  if (result != usb::Result::kOk) {
    error = std::string("arming failed: ") + usb::describe(result);
    return false;
  }
  // The ARM took 1-3 ms (up to its timeout), and the device's frames meanwhile took the restart
  // above and raised the drive while the set-points carried 0: restart again, then let the
  // drive through. Release, so that the event thread that sees armed_ sees this restart.
  latestDrive_.store(kRestartPending, std::memory_order_relaxed);
  armed_.store(true, std::memory_order_release);
  return true;
}

bool UsbBoardBackend::disarm(std::string& error) {
  armed_.store(false);  // set-points carry 0 from now on, whatever the board answers
  std::lock_guard<std::mutex> lock(commandMutex_);
  if (!connected_.load()) return true;
  const usb::Result result = control(kVendorOut, static_cast<uint8_t>(board::Request::kDisarm), 0, nullptr, 0, nullptr);
  if (result != usb::Result::kOk) {
    error = std::string("disarming failed: ") + usb::describe(result);
    return false;
  }
  return true;
}

void UsbBoardBackend::commandForce(double timeS, float forceN) {
  const double span = options_.maxForceN - options_.minForceN;
  const double drive = span > 0.0 ? (forceN - options_.minForceN) / span : 0.0;
  commandDrive(timeS, forceN, static_cast<float>(drive));
}

void UsbBoardBackend::commandDrive(double, float, float driveLevel) {
  const double level = std::isfinite(driveLevel) ? std::clamp(static_cast<double>(driveLevel), 0.0, 1.0) : 0.0;
  const auto drive = static_cast<uint32_t>(std::lround(level * board::kDriveFull));
  // A compare-exchange: a frame computed before ARM's restart never overwrites it.
  uint32_t current = latestDrive_.load(std::memory_order_relaxed);
  do {
    if (current & kRestartPending) return;
  } while (!latestDrive_.compare_exchange_weak(current, drive, std::memory_order_relaxed));
  if (options_.subSetPoints <= 1) return;
  const uint64_t index = written_.load(std::memory_order_relaxed);
  ring_[index % kRingSize].store(static_cast<uint16_t>(drive), std::memory_order_relaxed);
  written_.store(index + 1, std::memory_order_release);
}

// driveOff runs in signal handlers too (ForceBackend::driveOffFromSignal): its atomics must not lock.
static_assert(std::atomic<uint64_t>::is_always_lock_free && std::atomic<uint32_t>::is_always_lock_free);

void UsbBoardBackend::voidQueuedLevels() {
  voidBefore_.store(written_.load(std::memory_order_acquire), std::memory_order_relaxed);
  offs_.fetch_add(1, std::memory_order_release);
}

void UsbBoardBackend::driveOff() {
  latestDrive_.fetch_and(kRestartPending, std::memory_order_relaxed);
  voidQueuedLevels();
}

bool UsbBoardBackend::takeRestartFromOff() {
  uint32_t current = latestDrive_.load(std::memory_order_relaxed);
  while (current & kRestartPending)
    if (latestDrive_.compare_exchange_weak(current, 0, std::memory_order_relaxed)) {
      voidQueuedLevels();
      return true;
    }
  return false;
}

BoardTelemetry UsbBoardBackend::telemetry() const {
  std::lock_guard<PiMutex> lock(telemetryMutex_);
  BoardTelemetry copy = telemetry_;
  copy.connected = connected_.load();
  copy.armed = armed_.load();
  return copy;
}

// --- event thread ---------------------------------------------------------------------------

void UsbBoardBackend::onTransfer(usb::Transfer& transfer) {
  auto* self = static_cast<UsbBoardBackend*>(transfer.user);
  if (&transfer == &self->statusTransfer_)
    self->onStatus(transfer);
  else
    self->onSetPoint(transfer);
}

bool UsbBoardBackend::nextSubSetPoints(board::MultiSetPoint& frame) {
  if (options_.subSetPoints <= 1) return false;
  const int per = levelsPerSubSetPoint_;
  const uint64_t written = written_.load(std::memory_order_acquire);
  const uint64_t offs = offs_.load(std::memory_order_acquire);
  if (offs != seenOffs_) heldLevel_ = 0;  // an off or a restart since: nothing to hold
  seenOffs_ = offs;
  uint64_t from = std::max(taken_, voidBefore_.load(std::memory_order_relaxed));
  // More than two frames' worth waiting (the device ran ahead of the bus): the oldest go, so
  // the force is at most two frames behind.
  const uint64_t waitingGroups = (written - from) / per;
  if (waitingGroups > 2 * static_cast<uint64_t>(subSetPoints_)) {
    const uint64_t dropped = waitingGroups - subSetPoints_;  // whole groups: the means stay aligned
    from += dropped * per;
    std::lock_guard<PiMutex> lock(telemetryMutex_);
    telemetry_.subStepsDropped += dropped;
  }
  const auto groups = static_cast<int>(std::min<uint64_t>((written - from) / per, subSetPoints_));
  // A group not yet made holds the last level sent (a mean, to a 2.0 board, like the others).
  uint16_t last = heldLevel_;
  frame.count = subSetPoints_;
  for (int g = 0; g < subSetPoints_; ++g) {
    if (g < groups) {
      uint32_t sum = 0;
      for (int k = 0; k < per; ++k)
        sum += ring_[(from + static_cast<uint64_t>(g * per + k)) % kRingSize].load(std::memory_order_relaxed);
      last = static_cast<uint16_t>((sum + per / 2) / per);
    }
    frame.drives[g] = last;
  }
  // The writer went round the ring while it was read (never at 8 kHz: the ring holds 8 ms):
  // those levels are lost, counted as dropped, and the last level sent holds.
  if (written_.load(std::memory_order_acquire) > from + kRingSize) {
    std::fill(frame.drives, frame.drives + subSetPoints_, heldLevel_);
    std::lock_guard<PiMutex> lock(telemetryMutex_);
    telemetry_.subStepsDropped += static_cast<uint64_t>(groups);
  }
  heldLevel_ = frame.drives[subSetPoints_ - 1];
  taken_ = from + static_cast<uint64_t>(groups) * per;
  if (groups < subSetPoints_) {
    std::lock_guard<PiMutex> lock(telemetryMutex_);
    telemetry_.subStepsPadded += static_cast<uint64_t>(subSetPoints_ - groups);
  }
  return true;
}

void UsbBoardBackend::submitSetPoint(int slot) {
  usb::Transfer& transfer = outTransfers_[slot];
  const bool armed = armed_.load(std::memory_order_acquire);  // acquire: see arm()
  board::MultiSetPoint frame;
  const bool several = nextSubSetPoints(frame);
  if (!armed || (latestDrive_.load(std::memory_order_relaxed) & kRestartPending))
    std::fill(frame.drives, frame.drives + board::kMaxSubSetPoints, 0);
  frame.sequence = ++sequence_;
  uint16_t drive = armed ? latestDrive() : 0;
  if (several && subSetPoints_ > 1) {
    board::encodeMultiSetPoint(frame, transfer.buffer);
    drive = frame.drives[frame.count - 1];
  } else {
    if (several) drive = frame.drives[0];  // a 2.0 board: the millisecond's mean
    board::encodeSetPoint({frame.sequence, drive}, transfer.buffer);
  }
  const usb::Result result = port_->submit(transfer);
  if (result == usb::Result::kOk) {
    outBusy_[slot] = true;
    std::lock_guard<PiMutex> lock(telemetryMutex_);
    telemetry_.lastSequenceSent = sequence_;
    telemetry_.lastDriveSent = drive;
  } else if (result == usb::Result::kNoDevice) {
    markUnplugged();
  } else {
    std::lock_guard<PiMutex> lock(telemetryMutex_);
    ++telemetry_.lostTransfers;
  }
}

void UsbBoardBackend::submitStatus() {
  const usb::Result result = port_->submit(statusTransfer_);
  if (result == usb::Result::kOk)
    statusBusy_ = true;
  else if (result == usb::Result::kNoDevice)
    markUnplugged();
}

void UsbBoardBackend::submitIdle() {
  if (stopping_.load() || unplugged_ || !connected_.load() || steadyS() < retryAfterS_) return;
  const int inFlight = std::clamp(options_.transfersInFlight, 1, kMaxInFlight);
  for (int slot = 0; slot < inFlight && !haltOut_ && !unplugged_; ++slot)
    if (!outBusy_[slot]) submitSetPoint(slot);
  if (!statusBusy_ && !haltIn_ && !unplugged_) submitStatus();
}

void UsbBoardBackend::markUnplugged() {
  if (unplugged_) return;
  unplugged_ = true;
  std::lock_guard<PiMutex> lock(telemetryMutex_);
  ++telemetry_.unplugs;
  telemetry_.lastError = "the friction board was unplugged";
}

void UsbBoardBackend::onSetPoint(usb::Transfer& transfer) {
  if (&transfer == &zeroTransfer_) {
    zeroBusy_ = false;
    return;
  }
  const int slot = static_cast<int>(&transfer - outTransfers_);
  outBusy_[slot] = false;
  const double nowS = steadyS();
  {
    std::lock_guard<PiMutex> lock(telemetryMutex_);
    switch (transfer.status) {
      case usb::TransferStatus::kCompleted:
        if (transfer.actualLength == transfer.length) {
          ++telemetry_.setPointsSent;
          if (lastOutDoneS_ >= 0.0 && nowS - lastOutDoneS_ > options_.lateTransferS) ++telemetry_.lateTransfers;
          lastOutDoneS_ = nowS;
        } else {
          ++telemetry_.partials;
          ++telemetry_.lostTransfers;
        }
        break;
      case usb::TransferStatus::kTimedOut:
        ++telemetry_.timeouts;
        ++telemetry_.lostTransfers;
        break;
      case usb::TransferStatus::kStall:
        ++telemetry_.stalls;
        haltOut_ = true;
        return;  // resubmitted once every OUT transfer is back and the halt is cleared
      case usb::TransferStatus::kNoDevice:
        break;
      case usb::TransferStatus::kCancelled:
        return;
      default:
        ++telemetry_.lostTransfers;
        break;
    }
  }
  if (transfer.status == usb::TransferStatus::kNoDevice) {
    markUnplugged();
    return;
  }
  if (failedAtOnce(transfer.status)) return;  // the loop sends it again, a millisecond on
  if (!stopping_.load() && !unplugged_ && !haltOut_) submitSetPoint(slot);
}

void UsbBoardBackend::onStatus(usb::Transfer& transfer) {
  statusBusy_ = false;
  if (transfer.status == usb::TransferStatus::kNoDevice) {
    markUnplugged();
    return;
  }
  if (transfer.status == usb::TransferStatus::kCancelled) return;
  if (transfer.status == usb::TransferStatus::kStall) {
    // A halted status endpoint is cleared in the loop like the set-point one.
    haltIn_ = true;
    std::lock_guard<PiMutex> lock(telemetryMutex_);
    ++telemetry_.stalls;
    return;
  }
  board::Status status;
  const bool valid = transfer.status == usb::TransferStatus::kCompleted &&
                     board::decodeStatus(transfer.buffer, static_cast<size_t>(transfer.actualLength), status);
  {
    std::lock_guard<PiMutex> lock(telemetryMutex_);
    if (valid) {
      telemetry_.status = status;
      telemetry_.haveStatus = true;
    } else if (transfer.status != usb::TransferStatus::kTimedOut) {
      ++telemetry_.badStatus;
    }
  }
  if (failedAtOnce(transfer.status)) return;
  if (!stopping_.load() && !unplugged_) submitStatus();
}

bool UsbBoardBackend::failedAtOnce(usb::TransferStatus status) {
  // A transfer that failed (not a timeout, stall, cancel or unplug) may fail again as soon as it
  // is sent: a device going away fails every transfer at once (EPROTO, before the kernel has
  // seen it go). Sent again from its callback, it would keep this realtime thread busy, and on a
  // machine with one CPU starve the kernel's own hub work, so that the unplug is never seen
  // (tests/kernel: test_board_gadget.cpp). So it waits a set-point period, sent by the loop.
  if (status != usb::TransferStatus::kError && status != usb::TransferStatus::kOverflow) return false;
  retryAfterS_ = steadyS() + kRetryAfterErrorS;
  return true;
}

bool UsbBoardBackend::anyOutInFlight() const {
  if (zeroBusy_) return true;
  for (bool busy : outBusy_)
    if (busy) return true;
  return false;
}

bool UsbBoardBackend::anyInFlight() const { return statusBusy_ || anyOutInFlight(); }

bool UsbBoardBackend::waitForTransfers() {
  // No shorter bound: a transfer's callback may come as late as its timeout, or later under
  // load, and until it ran libusb owns the transfer (UsbPort.hpp).
  const double deadlineS = steadyS() + options_.callbackWaitS;
  while (anyInFlight()) {
    if (steadyS() > deadlineS) {
      leaked_ = true;
      std::lock_guard<PiMutex> lock(telemetryMutex_);
      telemetry_.transfersLeaked = true;
      telemetry_.lastError =
          "a USB transfer never came back (it was not freed); restart the server to use the board again";
      return false;
    }
    port_->handleEvents(5);
  }
  return true;
}

void UsbBoardBackend::cancelAll() {
  for (int slot = 0; slot < kMaxInFlight; ++slot)
    if (outBusy_[slot]) port_->cancel(outTransfers_[slot]);
  if (statusBusy_) port_->cancel(statusTransfer_);
  if (zeroBusy_) port_->cancel(zeroTransfer_);
}

void UsbBoardBackend::dropHandle() {
  std::lock_guard<std::mutex> lock(portMutex_);
  connected_.store(false);
  armed_.store(false);
  port_->releaseInterface(board::kInterfaceNumber);
  port_->close(0.0);  // waitForTransfers waited already: the port does not wait again
}

void UsbBoardBackend::run() {
  eventThreadId_.store(std::this_thread::get_id());
  threadScheduling_.store(scheduleThisThread("usb", options_.thread));
  submitIdle();
  while (!stopping_.load()) {
    if (connected_.load()) {
      port_->handleEvents(5);
      serveControl();
      if (unplugged_) {
        cancelAll();
        waitForTransfers();  // they come back with kNoDevice: only then is the handle dropped
        dropHandle();
        nextReopenS_ = steadyS() + options_.reopenPeriodS;
        continue;
      }
      // A halt is cleared only on an endpoint with nothing in flight (libusb_clear_halt).
      if (haltOut_ && !anyOutInFlight()) {
        if (port_->clearHalt(endpoints_.out) == usb::Result::kNoDevice) markUnplugged();
        haltOut_ = false;
      }
      if (haltIn_ && !statusBusy_) {
        if (port_->clearHalt(endpoints_.in) == usb::Result::kNoDevice) markUnplugged();
        haltIn_ = false;
      }
      submitIdle();
    } else {
      {
        std::unique_lock<std::mutex> lock(wakeMutex_);
        wake_.wait_for(lock, std::chrono::duration<double>(std::max(0.0, nextReopenS_ - steadyS())),
                       [this] { return stopping_.load() || controlRequest_ != nullptr; });
      }
      if (stopping_.load()) break;
      serveControl();  // no handle: the port answers kNoDevice
      if (steadyS() < nextReopenS_) continue;
      std::string error;
      std::lock_guard<std::mutex> lock(portMutex_);
      if (connectLocked(error)) {
        // Found again: a fresh board, disarmed until armed again.
        armed_.store(false);
        unplugged_ = false;
        haltOut_ = haltIn_ = false;
        lastOutDoneS_ = -1.0;
        std::lock_guard<PiMutex> telemetryLock(telemetryMutex_);
        ++telemetry_.reopens;
        telemetry_.lastError.clear();
        // Nothing tells a board without a serial from another with its IDs: it is taken, but
        // the user is told (disarmed, and no calibration table can be loaded for it).
        if (ids_.serial.empty())
          telemetry_.lastError =
              "a board without a USB serial was plugged in: it may be another board than before; it is disarmed";
        // Connected only with its status written, under the lock telemetry() reads under: a status
        // read between the two said connected with no warning (a fresh clone beside a second
        // test command, the Windows suite under Wine).
        connected_.store(true);
      } else {
        nextReopenS_ = steadyS() + options_.reopenPeriodS;
      }
    }
  }
  shutdownLink();
  std::lock_guard<std::mutex> lock(wakeMutex_);
  eventThreadServes_ = false;
  eventThreadId_.store(std::thread::id());  // a later thread may get this id
  if (controlRequest_ != nullptr) {         // posted after the loop ended: never sent
    controlRequest_->result = usb::Result::kNoDevice;
    controlRequest_->done = true;
    controlRequest_ = nullptr;
  }
  controlDone_.notify_all();
}

void UsbBoardBackend::shutdownLink() {
  if (connected_.load() && !unplugged_) {
    // Cancel what is queued and wait for every callback, so no transfer is left in flight.
    cancelAll();
    const bool allBack = waitForTransfers();
    // The last set-point: drive 0 (unless a transfer was given up: DISARM does it). Then
    // DISARM, release, close.
    board::encodeSetPoint({++sequence_, 0}, zeroTransfer_.buffer);
    if (allBack && port_->submit(zeroTransfer_) == usb::Result::kOk) {
      zeroBusy_ = true;
      const double giveUpS = steadyS() + 0.1;  // a board that takes nothing: DISARM does it
      while (zeroBusy_ && steadyS() < giveUpS) port_->handleEvents(5);
      cancelAll();
      waitForTransfers();
    }
    armed_.store(false);
    std::lock_guard<std::mutex> lock(portMutex_);
    control(kVendorOut, static_cast<uint8_t>(board::Request::kDisarm), 0, nullptr, 0, nullptr);
  } else if (connected_.load()) {
    cancelAll();
    waitForTransfers();
  }
  if (connected_.load()) dropHandle();
  std::lock_guard<std::mutex> lock(portMutex_);
  port_->exit();
}

}  // namespace kf
