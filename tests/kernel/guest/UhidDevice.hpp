// UhidDevice: a HID device made from user space through /dev/uhid, the kernel's own way to add one
// (BlueZ makes Bluetooth LE mice this way): the HID core parses its report descriptor, hid-generic
// binds it, hidraw and hid-input (evdev) make nodes for it, exactly as for a USB device, and every
// input report written here reaches them as if it came over the bus. A thread answers the
// kernel's requests (GET_REPORT, SET_REPORT: refused, as a mouse without feature reports would).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

namespace kf::guest {

struct UhidIdentity {
  std::string name;
  std::string uniq;     // the serial (sysfs "uniq", hidapi's serial number)
  uint16_t bus = 0x03;  // BUS_USB
  uint16_t vendorId = 0, productId = 0;
};

class UhidDevice {
 public:
  // Creates the device (UHID_CREATE2); throws with the reason when the kernel refuses it.
  UhidDevice(const UhidIdentity& identity, const std::vector<uint8_t>& descriptor);
  ~UhidDevice();  // UHID_DESTROY: the device and its nodes are removed (an unplug)
  UhidDevice(const UhidDevice&) = delete;
  UhidDevice& operator=(const UhidDevice&) = delete;

  // One input report as the device sends it (report ID first when it numbers its reports).
  void send(const std::vector<uint8_t>& report);
  void send(const uint8_t* bytes, size_t size);
  // True once the kernel has started the device (UHID_START: a driver bound it).
  bool started() const { return started_.load(); }

 private:
  void answerRequests();
  int fd_ = -1;
  std::atomic<bool> started_{false}, stop_{false};
  std::thread thread_;
};

}  // namespace kf::guest
