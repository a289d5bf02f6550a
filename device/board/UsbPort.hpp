// UsbPort: the little of libusb the board driver needs, behind our own interface, so the
// driver runs against the real libusb (makeLibusbPort) or the board emulator (tests): a
// context, open by IDs and serial, claim/release, synchronous control requests, asynchronous
// interrupt transfers (submit, cancel, callbacks run by handleEvents), clear halt, close.
// Thread rules: handleEvents on one thread, the event thread; submit and cancel from any; control
// only from the event thread while transfers are in flight, since a synchronous request handles
// events on its caller's thread (libusb_handle_events_completed) and would run their callbacks
// there.
// Life cycle (libusb's API docs, "asynchronous I/O"): a submitted transfer is the library's
// until its callback ran — cancel only asks for that callback, so its storage is not reused or
// freed before; clearHalt only on an endpoint with no transfer in flight ("cancel all pending
// transfers before attempting to clear the halt condition", libusb_clear_halt).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace kf::usb {

// The outcomes the driver tells apart (libusb's error codes, reduced).
enum class Result {
  kOk,
  kIo,
  kInvalid,
  kAccess,
  kNoDevice,
  kNotFound,
  kBusy,
  kTimeout,
  kPipe,
  kLeaked,
  kOther,
  kNotBuilt  // a build without hardware backends (KF_WITH_HARDWARE=OFF): no libusb
};
const char* describe(Result result);

enum class TransferStatus { kCompleted, kError, kTimedOut, kCancelled, kStall, kNoDevice, kOverflow };
const char* describe(TransferStatus status);

// One asynchronous interrupt transfer, owned by the caller and reused: fill endpoint, length,
// buffer (OUT), timeout and callback; submit; the callback runs on the handleEvents thread
// with status and actualLength set. Its storage must outlive the port's close().
struct Transfer {
  static constexpr int kCapacity = 64;
  uint8_t endpoint = 0;  // bit 7 set: IN
  int length = 0;        // bytes to send, or room to receive
  unsigned timeoutMs = 0;
  uint8_t buffer[kCapacity] = {};
  void (*callback)(Transfer& transfer) = nullptr;
  void* user = nullptr;
  // Set before the callback runs.
  TransferStatus status = TransferStatus::kCompleted;
  int actualLength = 0;
  void* impl = nullptr;  // the port's own (libusb_transfer*)
};

// The interface a device must have to be ours: checked from its descriptors before it is
// opened, so a stranger that shares the IDs (test IDs are shared) is never opened, claimed or
// detached from its kernel driver.
struct InterfaceIdentity {
  int number = 0;
  uint8_t interfaceClass = 0;
  uint8_t subclass = 0;
  uint8_t protocol = 0;
};

// What keeps a device from being ours: "" when interface `found` is `wanted`; else e.g.
// "interface 0 is class 03/01/02, not ff/4b/01" (class/subclass/protocol).
// found == nullptr: the device has no such interface.
std::string interfaceMismatch(const InterfaceIdentity* found, const InterfaceIdentity& wanted);

// The interface's interrupt endpoints, read from its descriptors: set-points OUT, status IN.
// PROTOCOL.md section 1 asks for 0x01 and 0x81, but a device controller may number them
// otherwise (dummy_hcd gives a FunctionFS function's interrupt OUT endpoint 0x02), so the host
// takes them from the interface. 0: none.
struct InterfaceEndpoints {
  uint8_t out = 0;
  uint8_t in = 0;
};

struct DeviceIds {
  uint16_t vendorId = 0;
  uint16_t productId = 0;
  std::string serial;  // empty: the first device with the IDs
  InterfaceIdentity iface;
};

class Port {
 public:
  virtual ~Port() = default;
  virtual Result init() = 0;  // an own context, not libusb's default one
  virtual void exit() = 0;
  // Opens the device with these IDs (and serial) whose interface ids.iface.number has the
  // class, subclass and protocol of ids.iface. kNotFound when none matches; skipped() then
  // names the devices that had the IDs but not the interface (left untouched).
  virtual Result open(const DeviceIds& ids) = 0;
  virtual std::string skipped() const = 0;
  virtual std::string openSerial() const = 0;            // of the open device
  virtual InterfaceEndpoints openEndpoints() const = 0;  // of the open device's interface
  // Never detaches a kernel driver: kBusy when one (or another program) holds the interface.
  virtual Result claimInterface(int number) = 0;
  virtual void releaseInterface(int number) = 0;
  // Every transfer must be back first (its callback ran); one that is not is cancelled and
  // waited for up to callbackWaitS (what is left of the caller's own wait: 0 once it gave up),
  // and if it has not come back then it is leaked with its handle, never freed; open() then
  // answers kLeaked.
  virtual void close(double callbackWaitS) = 0;
  // Synchronous control request; *transferred gets the data bytes moved. On the event thread
  // (above): it runs the callbacks that come due meanwhile.
  virtual Result control(uint8_t requestType, uint8_t request, uint16_t value, uint16_t index, uint8_t* data,
                         uint16_t length, unsigned timeoutMs, int* transferred) = 0;
  virtual Result clearHalt(uint8_t endpoint) = 0;
  virtual Result submit(Transfer& transfer) = 0;
  virtual Result cancel(Transfer& transfer) = 0;
  // Waits up to timeoutMs for transfer events and runs the callbacks of finished transfers.
  virtual Result handleEvents(int timeoutMs) = 0;
};

// libusb-1.0 (LibusbPort.cpp); in a build without hardware backends a port whose init() answers
// kNotBuilt (LibusbPortAbsent.cpp).
std::unique_ptr<Port> makeLibusbPort();

}  // namespace kf::usb
