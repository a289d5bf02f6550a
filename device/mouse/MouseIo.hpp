// MouseIo: our own small interfaces over the calls the real-mouse backends make — hidapi
// (enumerate, open by path, read with a timeout, close, the report descriptor) and a Linux
// evdev node (open, EVIOCSCLOCKID, EVIOCGRAB, EVIOCGNAME, EVIOCGID, read input_event). The
// backends only see these, so tests put fakes behind them that replay recorded devices in real
// time and fail as the real ones do. Real implementations: HidapiIo.cpp, EvdevIoLinux.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace kf {

// Why an open failed, so the caller can tell the user what to do.
enum class OpenFailure { kNone, kPermission, kNotFound, kOther };

// One mouse a backend could open (usage page 1, usage 2 for hidapi; REL_X and REL_Y and no
// keyboard keys for evdev).
struct MouseInfo {
  std::string path;  // hidapi path (/dev/hidrawN on Linux) or /dev/input/eventN
  uint16_t vendorId = 0, productId = 0;
  std::string serial, manufacturer, product;
  int interfaceNumber = -1;
  uint16_t usagePage = 0, usage = 0;
  // Where it is plugged in: its sysfs device path without the numbers the kernel hands out
  // anew at each plug-in (HID instance, input number), e.g. "pci0000:00/0000:00:14.0/usb1/1-2/
  // 1-2:1.0/0003:046D:C077". The same mouse in the same port (and interface, and for a
  // receiver the same paired device) has the same busPath after a replug. Empty: unknown.
  std::string busPath;
  bool external = true;       // USB or Bluetooth; false: built in (a trackpoint or touchpad: PS/2, I2C, SMBus)
  bool hasXY = true;          // its reports carry relative X and Y (hidapi: from the report descriptor)
  bool alsoKeyboard = false;  // hidapi: the node is a keyboard's too (evdev lists no such node)
  // evdev: the report descriptor of the HID device under the event node (sysfs), so that a
  // delta's saturation comes from its field's logical limits; empty for a mouse that is not HID
  // (PS/2, a trackpoint), whose limits the backend can only guess.
  std::vector<uint8_t> hidDescriptor;
};

// --- hidapi -------------------------------------------------------------------------------

class HidHandle {
 public:
  virtual ~HidHandle() = default;  // closes (hid_close); only by the thread that reads
  // hid_read_timeout: bytes read (> 0), 0 on timeout, -1 on error (unplug: see lastError).
  virtual int readTimeout(uint8_t* buffer, size_t capacity, int timeoutMs) = 0;
  virtual std::string lastError() = 0;
  // The device's report descriptor; false with a message.
  virtual bool reportDescriptor(std::vector<uint8_t>& out, std::string& error) = 0;
};

class HidApi {
 public:
  virtual ~HidApi() = default;
  // Mice only (usage page 1, usage 2), in orderMice's order. False with a message when
  // enumeration itself failed; finding none is true with an empty list.
  virtual bool enumerateMice(std::vector<MouseInfo>& out, std::string& error) = 0;
  // Null with a message and a reason on failure.
  virtual std::unique_ptr<HidHandle> openPath(const std::string& path, std::string& error, OpenFailure& why) = 0;
};

// hidapi (hidraw backend on Linux). hid_init once per process, on first use. Its calls that
// touch hidapi's global state (hid_init, hid_enumerate, hid_open_path and the global error
// string) are serialised by one mutex: the reader threads re-open while commands list and open.
std::shared_ptr<HidApi> realHidApi();

// --- evdev --------------------------------------------------------------------------------

// The fields of struct input_event the backend uses, with its time as seconds.
struct EvdevEvent {
  double timeS = 0.0;
  uint16_t type = 0, code = 0;
  int32_t value = 0;
};

class EvdevHandle {
 public:
  virtual ~EvdevHandle() = default;                              // closes the fd; only by the thread that reads
  virtual bool setMonotonicClock(std::string& error) = 0;        // EVIOCSCLOCKID CLOCK_MONOTONIC
  virtual bool grab(bool on, std::string& error) = 0;            // EVIOCGRAB
  virtual std::string name() = 0;                                // EVIOCGNAME
  virtual bool id(uint16_t& vendorId, uint16_t& productId) = 0;  // EVIOCGID
  // EVIOCGKEY: which of BTN_LEFT .. BTN_TASK are down now (bit i = button i + 1); false on error.
  virtual bool buttonsDown(uint32_t& buttons) = 0;
  // Waits up to timeoutMs for events and reads whole input_events: how many (> 0), 0 on
  // timeout, -1 with *errnoOut set (ENODEV: unplugged).
  virtual int read(EvdevEvent* out, int capacity, int timeoutMs, int* errnoOut) = 0;
};

class EvdevApi {
 public:
  virtual ~EvdevApi() = default;
  // Nodes whose capabilities have REL_X and REL_Y and no keyboard keys (from sysfs: needs no
  // permission), in orderMice's order.
  virtual bool enumerateMice(std::vector<MouseInfo>& out, std::string& error) = 0;
  virtual std::unique_ptr<EvdevHandle> open(const std::string& path, std::string& error, OpenFailure& why) = 0;
};

// Linux evdev; on other systems enumerates nothing and fails to open.
std::shared_ptr<EvdevApi> realEvdevApi();
// The same, enumerating a copy of /sys/class/input elsewhere (tests build one with the nodes
// of devices this machine does not have).
std::shared_ptr<EvdevApi> evdevApiReadingSysfsAt(const std::string& sysClassInput);

// The message for a node the user may not open: names it and the fix (the udev rule).
std::string permissionFix(const std::string& path);

}  // namespace kf
