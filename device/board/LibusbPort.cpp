// UsbPort over libusb-1.0: its own context, asynchronous interrupt transfers, events handled
// on the caller's thread.
#include <libusb.h>

#include <cstring>
#include <mutex>
#include <vector>

#include "board/UsbPort.hpp"

namespace kf::usb {

const char* describe(Result result) {
  switch (result) {
    case Result::kOk:
      return "ok";
    case Result::kIo:
      return "input/output error";
    case Result::kInvalid:
      return "invalid parameter";
    case Result::kAccess:
      return "permission denied (is the udev rule of device/board/PROTOCOL.md installed?)";
    case Result::kNoDevice:
      return "no device (unplugged)";
    case Result::kNotFound:
      return "not found";
    case Result::kBusy:
      return "busy (another program has claimed the board)";
    case Result::kTimeout:
      return "timed out";
    case Result::kPipe:
      return "stall (the board refused the request)";
    case Result::kOther:
      break;
  }
  return "error";
}

const char* describe(TransferStatus status) {
  switch (status) {
    case TransferStatus::kCompleted:
      return "completed";
    case TransferStatus::kError:
      return "error";
    case TransferStatus::kTimedOut:
      return "timed out";
    case TransferStatus::kCancelled:
      return "cancelled";
    case TransferStatus::kStall:
      return "stall";
    case TransferStatus::kNoDevice:
      return "no device";
    case TransferStatus::kOverflow:
      return "overflow";
  }
  return "?";
}

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

class LibusbPort : public Port {
 public:
  ~LibusbPort() override {
    close();
    exit();
  }

  Result init() override {
    if (context_ != nullptr) return Result::kOk;
    return resultOf(libusb_init(&context_));
  }

  void exit() override {
    if (context_ == nullptr) return;
    libusb_exit(context_);
    context_ = nullptr;
  }

  Result open(const DeviceIds& ids) override {
    if (context_ == nullptr) return Result::kInvalid;
    close();
    libusb_device** list = nullptr;
    const ssize_t count = libusb_get_device_list(context_, &list);
    if (count < 0) return resultOf(static_cast<int>(count));
    Result result = Result::kNotFound;
    for (ssize_t i = 0; i < count && handle_ == nullptr; ++i) {
      libusb_device_descriptor descriptor;
      if (libusb_get_device_descriptor(list[i], &descriptor) != 0) continue;
      if (descriptor.idVendor != ids.vendorId || descriptor.idProduct != ids.productId) continue;
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
      result = Result::kOk;
    }
    libusb_free_device_list(list, 1);
    return result;
  }

  std::string openSerial() const override { return serial_; }

  Result claimInterface(int number) override {
    if (handle_ == nullptr) return Result::kInvalid;
    libusb_set_auto_detach_kernel_driver(handle_, 1);  // no kernel driver binds a vendor interface; harmless
    return resultOf(libusb_claim_interface(handle_, number));
  }

  void releaseInterface(int number) override {
    if (handle_ != nullptr) libusb_release_interface(handle_, number);
  }

  void close() override {
    if (handle_ != nullptr) {
      libusb_close(handle_);
      handle_ = nullptr;
    }
    std::lock_guard<std::mutex> lock(transfersMutex_);
    for (libusb_transfer* transfer : transfers_) {
      if (transfer->user_data != nullptr) static_cast<Transfer*>(transfer->user_data)->impl = nullptr;
      libusb_free_transfer(transfer);
    }
    transfers_.clear();
  }

  Result control(uint8_t requestType, uint8_t request, uint16_t value, uint16_t index, uint8_t* data, uint16_t length,
                 unsigned timeoutMs, int* transferred) override {
    if (handle_ == nullptr) return Result::kNoDevice;
    const int moved = libusb_control_transfer(handle_, requestType, request, value, index, data, length, timeoutMs);
    if (transferred != nullptr) *transferred = moved < 0 ? 0 : moved;
    return resultOf(moved);
  }

  Result clearHalt(uint8_t endpoint) override {
    if (handle_ == nullptr) return Result::kNoDevice;
    return resultOf(libusb_clear_halt(handle_, endpoint));
  }

  Result submit(Transfer& transfer) override {
    if (handle_ == nullptr) return Result::kNoDevice;
    auto* raw = static_cast<libusb_transfer*>(transfer.impl);
    if (raw == nullptr) {
      raw = libusb_alloc_transfer(0);
      if (raw == nullptr) return Result::kOther;
      raw->user_data = &transfer;
      std::lock_guard<std::mutex> lock(transfersMutex_);
      transfers_.push_back(raw);
      transfer.impl = raw;
    }
    libusb_fill_interrupt_transfer(raw, handle_, transfer.endpoint, transfer.buffer, transfer.length, &onDone,
                                   &transfer, transfer.timeoutMs);
    return resultOf(libusb_submit_transfer(raw));
  }

  Result cancel(Transfer& transfer) override {
    auto* raw = static_cast<libusb_transfer*>(transfer.impl);
    if (raw == nullptr) return Result::kNotFound;
    return resultOf(libusb_cancel_transfer(raw));
  }

  Result handleEvents(int timeoutMs) override {
    if (context_ == nullptr) return Result::kInvalid;
    timeval timeout{timeoutMs / 1000, (timeoutMs % 1000) * 1000};
    return resultOf(libusb_handle_events_timeout_completed(context_, &timeout, nullptr));
  }

 private:
  static void LIBUSB_CALL onDone(libusb_transfer* raw) {
    auto& transfer = *static_cast<Transfer*>(raw->user_data);
    transfer.status = statusOf(raw->status);
    transfer.actualLength = raw->actual_length;
    if (transfer.callback != nullptr) transfer.callback(transfer);
  }

  libusb_context* context_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  std::string serial_;
  std::mutex transfersMutex_;
  std::vector<libusb_transfer*> transfers_;
};

}  // namespace

std::unique_ptr<Port> makeLibusbPort() { return std::make_unique<LibusbPort>(); }

}  // namespace kf::usb
