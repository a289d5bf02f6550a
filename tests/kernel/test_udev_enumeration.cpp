// Enumeration and permissions as a user meets them: the guest's real sysfs (QEMU's USB mouse and
// keyboard on xHCI, the PC's PS/2 mouse and keyboard, a uhid receiver with a keyboard and a mouse
// collection), systemd-udevd applying device/mouse/udev/70-kineticfriction.rules with its own
// rules, and the seat's user (uid 1000, logged in at seat0) opening nodes.
#include <fcntl.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cerrno>

#include "guest/GuestSystem.hpp"
#include "guest/UhidDevice.hpp"
#include "mouse/EvdevMouseBackend.hpp"
#include "mouse/HidapiMouseBackend.hpp"
#include "mouse/MouseSelect.hpp"

using namespace kf;
using namespace kf::guest;

namespace {

// A wireless receiver's two collections on one HID device, after HID 1.11's appendix B boot
// keyboard and mouse, with report IDs: report 1 a keyboard (8 modifier keys, a reserved byte, 6
// key codes 0..101; 5 LEDs out), report 2 a mouse (3 buttons, X, Y, wheel: 8 bits each).
const std::vector<uint8_t> kReceiverDescriptor = {
    0x05, 0x01, 0x09, 0x06, 0xA1, 0x01, 0x85, 0x01,                                                  // Keyboard, ID 1
    0x05, 0x07, 0x19, 0xE0, 0x29, 0xE7, 0x15, 0x00, 0x25, 0x01, 0x75, 0x01, 0x95, 0x08, 0x81, 0x02,  // modifiers
    0x95, 0x01, 0x75, 0x08, 0x81, 0x01,                                                              // reserved
    0x95, 0x05, 0x75, 0x01, 0x05, 0x08, 0x19, 0x01, 0x29, 0x05, 0x91, 0x02,                          // LEDs out
    0x95, 0x01, 0x75, 0x03, 0x91, 0x01,                                                              // padding
    0x95, 0x06, 0x75, 0x08, 0x15, 0x00, 0x25, 0x65, 0x05, 0x07, 0x19, 0x00, 0x29, 0x65, 0x81, 0x00,  // keys
    0xC0,                                                                                            //
    0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x85, 0x02, 0x09, 0x01, 0xA1, 0x00,                          // Mouse, ID 2
    0x05, 0x09, 0x19, 0x01, 0x29, 0x03, 0x15, 0x00, 0x25, 0x01, 0x95, 0x03, 0x75, 0x01, 0x81, 0x02,  // buttons
    0x95, 0x01, 0x75, 0x05, 0x81, 0x01,                                                              // padding
    0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x09, 0x38, 0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x03,
    0x81, 0x06, 0xC0, 0xC0};
const std::string kReceiverName = "KF guest receiver";

// A mouse whose own report carries two keyboard keys (a gaming mouse's macro keys): one
// application, so one input node that reports keys as well as motion.
const std::vector<uint8_t> kMouseWithKeysDescriptor = {
    0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x09, 0x01, 0xA1, 0x00,                                      // Mouse, Pointer
    0x05, 0x09, 0x19, 0x01, 0x29, 0x03, 0x15, 0x00, 0x25, 0x01, 0x95, 0x03, 0x75, 0x01, 0x81, 0x02,  // buttons
    0x95, 0x01, 0x75, 0x05, 0x81, 0x01,                                                              // padding
    0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06,  // X, Y
    0x05, 0x07, 0x19, 0x04, 0x29, 0x05, 0x15, 0x00, 0x25, 0x01, 0x75, 0x01, 0x95, 0x02, 0x81, 0x02,  // keys a, b
    0x95, 0x01, 0x75, 0x06, 0x81, 0x01,                                                              // padding
    0xC0, 0xC0};
const std::string kMouseWithKeysName = "KF guest mouse with keys";

bool tagged(const std::string& node, const std::string& tag) {
  return udevTags(node).find(":" + tag + ":") != std::string::npos;
}

std::vector<MouseInfo> listed(bool hidapi) {
  std::vector<MouseInfo> mice;
  std::string error;
  const bool ok = hidapi ? realHidApi()->enumerateMice(mice, error) : realEvdevApi()->enumerateMice(mice, error);
  INFO(error);
  REQUIRE(ok);
  return mice;
}

bool isListed(const std::vector<MouseInfo>& mice, const std::string& path) {
  return std::any_of(mice.begin(), mice.end(), [&](const MouseInfo& m) { return m.path == path; });
}

std::string names(const std::vector<MouseInfo>& mice) {
  std::string out;
  for (size_t i = 0; i < mice.size(); ++i) out += "\n  " + describeMouse(static_cast<int>(i), mice[i]);
  return out;
}

}  // namespace

TEST_CASE("udev applies our rules: the seat's user opens mice, never a node that reports keys", "[kernel][udev]") {
  UhidDevice receiver({kReceiverName, "kf-receiver-1", 0x03, 0x1209, 0x0030}, kReceiverDescriptor);
  UhidDevice mouseWithKeys({kMouseWithKeysName, "kf-keys-1", 0x03, 0x1209, 0x0032}, kMouseWithKeysDescriptor);
  REQUIRE(waitUntil(
      [&] {
        return eventNodesNamed(kReceiverName + " Mouse").size() == 1 &&
               eventNodesNamed(kReceiverName + " Keyboard").size() == 1 &&
               eventNodesNamed(kMouseWithKeysName).size() == 1;
      },
      20.0));
  udevSettle();

  struct Node {
    std::string what, path;
    bool mouse;  // the rules promise uaccess (and ID_INPUT_MOUSE without keys for event nodes)
  };
  std::vector<Node> nodes;
  const std::string qemuMouse = eventNodesNamed("QEMU QEMU USB Mouse").at(0);
  nodes.push_back({"QEMU's USB mouse (event)", qemuMouse, true});
  nodes.push_back({"QEMU's USB keyboard (event)", eventNodesNamed("QEMU QEMU USB Keyboard").at(0), false});
  nodes.push_back({"the PC's PS/2 keyboard (event)", eventNodesNamed("AT Translated Set 2 keyboard").at(0), false});
  nodes.push_back({"the receiver's mouse (event)", eventNodesNamed(kReceiverName + " Mouse").at(0), true});
  nodes.push_back({"the receiver's keyboard (event)", eventNodesNamed(kReceiverName + " Keyboard").at(0), false});
  nodes.push_back({"a mouse whose reports carry keys (event)", eventNodesNamed(kMouseWithKeysName).at(0), false});
  // hidraw: a boot mouse interface is granted; a boot keyboard's, and a receiver's node (its
  // keyboard's reports too), never.
  nodes.push_back({"QEMU's USB mouse (hidraw)", hidrawNodesNamed("QEMU QEMU USB Mouse").at(0), true});
  nodes.push_back({"QEMU's USB keyboard (hidraw)", hidrawNodesNamed("QEMU QEMU USB Keyboard").at(0), false});
  nodes.push_back({"the receiver (hidraw)", hidrawNodesNamed(kReceiverName).at(0), false});

  std::string outcomes;
  for (const Node& node : nodes) {
    INFO(node.what << " " << node.path << ", tags " << udevTags(node.path));
    const bool event = node.path.find("/input/") != std::string::npos;
    const auto properties = udevProperties(node.path);
    if (event && node.mouse) {
      CHECK(properties.count("ID_INPUT_MOUSE"));
      CHECK_FALSE(properties.count("ID_INPUT_KEY"));
    }
    if (event && !node.mouse) CHECK(properties.count("ID_INPUT_KEY"));  // a mouse too, for the one with keys
    CHECK(tagged(node.path, "uaccess") == node.mouse);
    // uaccess gave the seat's user an ACL (udev's builtin, 73-seat-late.rules) or nothing: root's
    // 0660/0600 nodes.
    const int error = openAsSeatUser(node.path, event ? O_RDONLY : O_RDWR);
    CHECK(error == (node.mouse ? 0 : EACCES));
    outcomes += "; " + node.what + (error == 0 ? " opened" : " refused");
  }
  reportFigure("udev", "as uid 1000:" + outcomes.substr(1));
}

TEST_CASE("enumeration over real sysfs: USB mice first in port order, built-in last, keyboards never listed",
          "[kernel][udev]") {
  UhidDevice receiver({kReceiverName, "kf-receiver-2", 0x03, 0x1209, 0x0031}, kReceiverDescriptor);
  UhidDevice mouseWithKeys({kMouseWithKeysName, "kf-keys-2", 0x03, 0x1209, 0x0033}, kMouseWithKeysDescriptor);
  REQUIRE(waitUntil(
      [&] {
        return eventNodesNamed(kReceiverName + " Mouse").size() == 1 && eventNodesNamed(kMouseWithKeysName).size() == 1;
      },
      20.0));
  udevSettle();
  const std::string keyboardNode = eventNodesNamed(kReceiverName + " Keyboard").at(0);
  const std::string withKeysNode = eventNodesNamed(kMouseWithKeysName).at(0);

  const std::vector<MouseInfo> evdev = listed(false);
  INFO("evdev lists:" << names(evdev));
  REQUIRE(evdev.size() == 3);  // QEMU's USB mouse, the receiver's mouse, the PS/2 mouse
  CHECK(evdev[0].vendorId == 0x0627);
  CHECK(evdev[0].external);
  CHECK(evdev[0].busPath.find("/usb1/1-1/1-1:1.0/0003:0627:0001") != std::string::npos);
  CHECK(evdev[1].product == kReceiverName + " Mouse");
  CHECK(evdev[1].busPath == "virtual/misc/uhid/0003:1209:0031/input");  // its input device's class folder
  CHECK_FALSE(evdev[2].external);                                       // the PS/2 mouse: built in
  CHECK_FALSE(isListed(evdev, keyboardNode));
  CHECK_FALSE(isListed(evdev, withKeysNode));  // a mouse, but it reports keys
  // "first" is QEMU's USB mouse; the keyboard's node is refused by path and never opened.
  MouseInfo first;
  std::string error;
  REQUIRE(selectMouse(evdev, "first", first, error));
  CHECK(first.path == evdev[0].path);
  CHECK_FALSE(selectMouse(evdev, keyboardNode, first, error));
  CHECK(error.find("is not a mouse this backend lists") != std::string::npos);
  CHECK_FALSE(EvdevMouseBackend::open(realEvdevApi(), keyboardNode, false, error));

  const std::vector<MouseInfo> hidapi = listed(true);
  INFO("hidapi lists:" << names(hidapi));
  // QEMU's USB mouse, the mouse with keys (hidapi finds no USB device above a uhid device and
  // calls it built in; its descriptor has no keyboard collection), then the receiver (a
  // keyboard's node too).
  REQUIRE(hidapi.size() == 3);
  CHECK(hidapi[0].vendorId == 0x0627);
  CHECK_FALSE(hidapi[0].alsoKeyboard);
  CHECK(hidapi[2].path == hidrawNodesNamed(kReceiverName).at(0));
  CHECK(hidapi[2].alsoKeyboard);
  reportFigure("enumeration", "evdev:" + names(evdev) + "\nhidapi:" + names(hidapi));
}
