// SysfsPath: what enumeration reads from sysfs about where a mouse is plugged in, kept apart
// from the I/O so that tests can give it the paths of devices this machine does not have.
#pragma once

#include <string>

namespace kf {

// A device's sysfs path (the realpath of /sys/class/hidraw/hidrawN/device or of
// /sys/class/input/eventN/device) as MouseInfo::busPath: without "/sys/devices/", without the
// input device ("inputN") and with the HID instance number cut off each HID device name
// ("0003:046D:C077.0012" -> "0003:046D:C077"): both are counted up at every plug-in, the port
// and interface part is not. A receiver's paired mouse (hid-logitech-dj) is a HID device
// under the receiver's: "usb1/1-2/1-2:1.2/0003:046D:C52B/0003:046D:4082".
std::string stableBusPath(const std::string& sysfsPath);

// The realpath of a sysfs link, "" when it is not there.
std::string resolveSysfs(const std::string& link);

}  // namespace kf
