// UsbPort over libusb-1.0: its own context, asynchronous interrupt transfers, events handled
// on the caller's thread.
#include <libusb.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <vector>

#include "board/UsbPort.hpp"

namespace kf::usb {

namespace {

Result resultOf(int code) {
  if (code >= 0) return Result::kOk;
  switch (code) {
    case LIBUSB_ERROR_IO:
      return Result::kIo;
    case LIBUSB_ERROR_INVALID_PARAM:
      return Result::kInvalid;
    case LIBUSB_ERROR_ACCESS:
      return Result::kAccess;
    case LIBUSB_ERROR_NO_DEVICE:
      return Result::kNoDevice;
    case LIBUSB_ERROR_NOT_FOUND:
      return Result::kNotFound;
    case LIBUSB_ERROR_BUSY:
      return Result::kBusy;
    case LIBUSB_ERROR_TIMEOUT:
      return Result::kTimeout;
    case LIBUSB_ERROR_PIPE:
      return Result::kPipe;
    default:
      return Result::kOther;
  }
}

TransferStatus statusOf(libusb_transfer_status status) {
  switch (status) {
    case LIBUSB_TRANSFER_COMPLETED:
      return TransferStatus::kCompleted;
    case LIBUSB_TRANSFER_TIMED_OUT:
      return TransferStatus::kTimedOut;
    case LIBUSB_TRANSFER_CANCELLED:
      return TransferStatus::kCancelled;
    case LIBUSB_TRANSFER_STALL:
      return TransferStatus::kStall;
    case LIBUSB_TRANSFER_NO_DEVICE:
      return TransferStatus::kNoDevice;
    case LIBUSB_TRANSFER_OVERFLOW:
      return TransferStatus::kOverflow;
    default:
      return TransferStatus::kError;
  }
}

// The identity of interface `number` (alternate setting 0) of the active configuration and its
// first interrupt OUT and IN endpoints, read from the cached descriptors without opening the
// device (Linux: sysfs).
bool readInterface(libusb_device* device, int number, InterfaceIdentity& out, InterfaceEndpoints& endpoints) {
  libusb_config_descriptor* config = nullptr;
  if (libusb_get_active_config_descriptor(device, &config) != 0 || config == nullptr) return false;
  bool found = false;
  for (int i = 0; i < config->bNumInterfaces && !found; ++i) {
    const libusb_interface& iface = config->interface[i];
    if (iface.num_altsetting < 1 || iface.altsetting[0].bInterfaceNumber != number) continue;
    const libusb_interface_descriptor& alt = iface.altsetting[0];
    out = {number, alt.bInterfaceClass, alt.bInterfaceSubClass, alt.bInterfaceProtocol};
    endpoints = {};
    for (int e = 0; e < alt.bNumEndpoints; ++e) {
      const libusb_endpoint_descriptor& endpoint = alt.endpoint[e];
      if ((endpoint.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK) != LIBUSB_TRANSFER_TYPE_INTERRUPT) continue;
      uint8_t& slot = (endpoint.bEndpointAddress & LIBUSB_ENDPOINT_IN) ? endpoints.in : endpoints.out;
      if (slot == 0) slot = endpoint.bEndpointAddress;
    }
    found = true;
  }
  libusb_free_config_descriptor(config);
  return found;
}

constexpr double kCallbackWaitS = 10.0;  // the destructor's wait: past this a transfer is leaked

// A leaked transfer keeps its handle open and the interface claimed in this process, so no
// port of it can use the board again (a new one would find the interface busy).
std::atomic<bool> gLeakedInProcess{false};

class LibusbPort : public Port {
 public:
  ~LibusbPort() override {
    close(kCallbackWaitS);
    exit();
  }

  Result init() override {
    if (context_ != nullptr) return Result::kOk;
    return resultOf(libusb_init(&context_));
  }

  void exit() override {
    // A context with a leaked transfer stays: libusb_exit would free what is still in flight.
    if (context_ == nullptr || leaked_) return;
    libusb_exit(context_);
    context_ = nullptr;
  }

  Result open(const DeviceIds& ids) override {
    if (context_ == nullptr) return Result::kInvalid;
    // The driver refuses on its own after it gave a transfer up (UsbBoardBackend::connectLocked,
    // tested on the emulator); this covers a new port in the same process, which no test here
    // can show: it takes a device or stack whose transfer never calls back.
    if (leaked_ || gLeakedInProcess.load()) return Result::kLeaked;
    close(0.0);
    skipped_.clear();
    libusb_device** list = nullptr;
    const ssize_t count = libusb_get_device_list(context_, &list);
    if (count < 0) return resultOf(static_cast<int>(count));
    Result result = Result::kNotFound;
    for (ssize_t i = 0; i < count && handle_ == nullptr; ++i) {
      libusb_device_descriptor descriptor;
      if (libusb_get_device_descriptor(list[i], &descriptor) != 0) continue;
      if (descriptor.idVendor != ids.vendorId || descriptor.idProduct != ids.productId) continue;
      // Ours only if the interface is: a stranger with the same (shared test) IDs is not opened.
      InterfaceIdentity found;
      InterfaceEndpoints endpoints;
      const bool present = readInterface(list[i], ids.iface.number, found, endpoints);
      std::string mismatch = interfaceMismatch(present ? &found : nullptr, ids.iface);
      if (mismatch.empty() && (endpoints.out == 0 || endpoints.in == 0))
        mismatch = "interface " + std::to_string(ids.iface.number) + " lacks an interrupt OUT or IN endpoint";
      if (!mismatch.empty()) {
        char where[64];
        std::snprintf(where, sizeof where, "bus %d device %d", libusb_get_bus_number(list[i]),
                      libusb_get_device_address(list[i]));
        skipped_ += (skipped_.empty() ? "" : "; ") + std::string(where) + ": " + mismatch;
        continue;
      }
      libusb_device_handle* handle = nullptr;
      const int opened = libusb_open(list[i], &handle);
      if (opened != 0) {
        result = resultOf(opened);  // e.g. kAccess: a board is there but not ours to open
        continue;
      }
      char serial[128] = "";
      if (descriptor.iSerialNumber != 0)
        libusb_get_string_descriptor_ascii(handle, descriptor.iSerialNumber, reinterpret_cast<unsigned char*>(serial),
                                           sizeof serial);
      if (!ids.serial.empty() && ids.serial != serial) {
        libusb_close(handle);
        continue;
      }
      handle_ = handle;
      serial_ = serial;
      endpoints_ = endpoints;
      result = Result::kOk;
    }
    libusb_free_device_list(list, 1);
    return result;
  }

  std::string skipped() const override { return skipped_; }
  std::string openSerial() const override { return serial_; }
  InterfaceEndpoints openEndpoints() const override { return endpoints_; }

  Result claimInterface(int number) override {
    if (handle_ == nullptr) return Result::kInvalid;
    // No kernel driver binds a vendor interface: one that is bound means the interface is not
    // what we think, and it is left alone (no libusb_detach_kernel_driver, no auto-detach).
    if (libusb_kernel_driver_active(handle_, number) == 1) return Result::kBusy;
    return resultOf(libusb_claim_interface(handle_, number));
  }

  void releaseInterface(int number) override {
    if (handle_ != nullptr) libusb_release_interface(handle_, number);
  }

  void close(double callbackWaitS) override {
    if (leaked_) return;
    // Cancel what is still in flight and wait for each callback before anything is freed, for
    // as long as the caller has left: once it gave up, not again.
    bool inFlight = cancelInFlight();
    if (inFlight && context_ != nullptr && callbackWaitS > 0.0) {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(callbackWaitS);
      while ((inFlight = anyInFlight()) && std::chrono::steady_clock::now() < deadline) {
        timeval timeout{0, 10000};
        libusb_handle_events_timeout_completed(context_, &timeout, nullptr);
      }
    }
    if (inFlight) {
      // Freeing now would let libusb write into freed memory: leak the transfers, the handle
      // and the context instead, and say so.
      std::fprintf(stderr, "KineticFriction: a USB transfer never came back; its handle is leaked\n");
      leaked_ = true;
      gLeakedInProcess.store(true);
      return;
    }
    if (handle_ != nullptr) {
      libusb_close(handle_);
      handle_ = nullptr;
    }
    std::lock_guard<std::mutex> lock(transfersMutex_);
    for (const std::unique_ptr<Owned>& owned : transfers_) {
      owned->transfer->impl = nullptr;
      libusb_free_transfer(owned->raw);
    }
    transfers_.clear();
  }

  Result control(uint8_t requestType, uint8_t request, uint16_t value, uint16_t index, uint8_t* data, uint16_t length,
                 unsigned timeoutMs, int* transferred) override {
    // Handles events on this thread until it completes: the event thread only (UsbPort.hpp).
    if (handle_ == nullptr) return Result::kNoDevice;
    const int moved = libusb_control_transfer(handle_, requestType, request, value, index, data, length, timeoutMs);
    if (transferred != nullptr) *transferred = moved < 0 ? 0 : moved;
    return resultOf(moved);
  }

  Result clearHalt(uint8_t endpoint) override {
    if (handle_ == nullptr) return Result::kNoDevice;
    if (endpointBusy(endpoint)) return Result::kBusy;  // the caller's bug: cancel and wait first
    return resultOf(libusb_clear_halt(handle_, endpoint));
  }

  Result submit(Transfer& transfer) override {
    if (handle_ == nullptr) return Result::kNoDevice;
    auto* owned = static_cast<Owned*>(transfer.impl);
    std::lock_guard<std::mutex> lock(transfersMutex_);
    if (owned == nullptr) {
      libusb_transfer* raw = libusb_alloc_transfer(0);
      if (raw == nullptr) return Result::kOther;
      transfers_.push_back(std::unique_ptr<Owned>(new Owned{raw, &transfer, false}));
      owned = transfers_.back().get();
      transfer.impl = owned;
    }
    if (owned->inFlight) return Result::kBusy;  // its callback has not run: not ours to refill
    libusb_fill_interrupt_transfer(owned->raw, handle_, transfer.endpoint, transfer.buffer, transfer.length, &onDone,
                                   owned, transfer.timeoutMs);
    // In flight before it is submitted: its callback may run on the event thread before
    // libusb_submit_transfer returns here, and clears it.
    owned->inFlight = true;
    const Result result = resultOf(libusb_submit_transfer(owned->raw));
    if (result != Result::kOk) owned->inFlight = false;
    return result;
  }

  Result cancel(Transfer& transfer) override {
    auto* owned = static_cast<Owned*>(transfer.impl);
    if (owned == nullptr) return Result::kNotFound;
    return resultOf(libusb_cancel_transfer(owned->raw));
  }

  Result handleEvents(int timeoutMs) override {
    if (context_ == nullptr) return Result::kInvalid;
    timeval timeout{timeoutMs / 1000, (timeoutMs % 1000) * 1000};
    return resultOf(libusb_handle_events_timeout_completed(context_, &timeout, nullptr));
  }

 private:
  struct Owned {
    libusb_transfer* raw;
    Transfer* transfer;
    std::atomic<bool> inFlight;  // submitted, its callback not yet run
  };

  static void LIBUSB_CALL onDone(libusb_transfer* raw) {
    auto* owned = static_cast<Owned*>(raw->user_data);
    Transfer& transfer = *owned->transfer;
    transfer.status = statusOf(raw->status);
    transfer.actualLength = raw->actual_length;
    owned->inFlight = false;  // the callback may resubmit it
    if (transfer.callback != nullptr) transfer.callback(transfer);
  }

  bool anyInFlight() {
    std::lock_guard<std::mutex> lock(transfersMutex_);
    for (const std::unique_ptr<Owned>& owned : transfers_)
      if (owned->inFlight) return true;
    return false;
  }

  bool endpointBusy(uint8_t endpoint) {
    std::lock_guard<std::mutex> lock(transfersMutex_);
    for (const std::unique_ptr<Owned>& owned : transfers_)
      if (owned->inFlight && owned->transfer->endpoint == endpoint) return true;
    return false;
  }

  bool cancelInFlight() {
    std::lock_guard<std::mutex> lock(transfersMutex_);
    bool any = false;
    for (const std::unique_ptr<Owned>& owned : transfers_)
      if (owned->inFlight) {
        libusb_cancel_transfer(owned->raw);
        any = true;
      }
    return any;
  }

  libusb_context* context_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  std::string serial_;
  InterfaceEndpoints endpoints_;
  std::string skipped_;
  bool leaked_ = false;
  std::mutex transfersMutex_;
  std::vector<std::unique_ptr<Owned>> transfers_;
};

}  // namespace

std::unique_ptr<Port> makeLibusbPort() { return std::make_unique<LibusbPort>(); }

}  // namespace kf::usb
