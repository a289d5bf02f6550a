// Which mouse "first" is, what an index means, and which mouse a re-open finds: the same
// whatever order enumeration returns, a USB mouse's X/Y interface before its vendor interface
// and before a built-in trackpoint or touchpad, the same port after a replug.
#include <algorithm>
#include <catch2/catch.hpp>
#include <thread>

#include "../WaitFor.hpp"
#include "FakeMouseIo.hpp"
#include "mouse/DescriptorKind.hpp"
#include "mouse/HidapiMouseBackend.hpp"
#include "mouse/MouseSelect.hpp"
#include "mouse/SysfsPath.hpp"

using namespace kf;
using kf::test::FakeHidApi;
using kf::test::FakeMouseScript;

namespace {

MouseInfo mouse(const std::string& path, uint16_t vid, uint16_t pid, const std::string& busPath, int interface,
                bool external = true, bool hasXY = true) {
  MouseInfo m;
  m.path = path, m.vendorId = vid, m.productId = pid, m.busPath = busPath, m.interfaceNumber = interface;
  m.external = external, m.hasXY = hasXY;
  return m;
}

// A laptop with a trackpoint (PS/2) and an I2C touchpad, and two USB mice: a gaming mouse whose
// vendor interface also declares a mouse collection (no X/Y), and a plain one in a lower port.
std::vector<MouseInfo> laptop() {
  return {
      mouse("/dev/hidraw0", 0x06cb, 0xcd8b, "pci0000:00/0000:00:15.1/i2c_designware.1/i2c-2/i2c-SYNA8008:00", -1,
            false),
      mouse("/dev/hidraw5", 0x1532, 0x0084, "pci0000:00/0000:00:14.0/usb1/1-3/1-3:1.1/0003:1532:0084", 1, true, false),
      mouse("/dev/hidraw4", 0x1532, 0x0084, "pci0000:00/0000:00:14.0/usb1/1-3/1-3:1.0/0003:1532:0084", 0),
      mouse("/dev/hidraw2", 0x046d, 0xc077, "pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.0/0003:046D:C077", 0),
      mouse("/dev/input/event6", 0x0002, 0x000a, "platform/i8042/serio1/serio2/input", -1, false)};
}

MouseInfo mouse_(const std::string& path, const std::string& busPath, bool alsoKeyboard) {
  MouseInfo m;
  m.path = path, m.busPath = busPath, m.alsoKeyboard = alsoKeyboard;
  return m;
}

std::vector<std::string> pathsInOrder(std::vector<MouseInfo> mice) {
  orderMice(mice);
  std::vector<std::string> paths;
  for (const MouseInfo& m : mice) paths.push_back(m.path);
  return paths;
}

}  // namespace

TEST_CASE("mice are ordered USB first, X/Y interfaces first, then by port, whatever enumeration gave",
          "[mouse][select]") {
  const std::vector<std::string> expected = {"/dev/hidraw2", "/dev/hidraw4", "/dev/hidraw5", "/dev/hidraw0",
                                             "/dev/input/event6"};
  std::vector<MouseInfo> mice = laptop();
  CHECK(pathsInOrder(mice) == expected);
  std::reverse(mice.begin(), mice.end());
  CHECK(pathsInOrder(mice) == expected);
  std::rotate(mice.begin(), mice.begin() + 2, mice.end());
  CHECK(pathsInOrder(mice) == expected);

  MouseInfo out;
  std::string error;
  REQUIRE(selectMouse(mice, "", out, error));
  CHECK(out.path == "/dev/hidraw2");  // never the trackpoint or touchpad while a USB mouse is in
  REQUIRE(selectMouse(mice, "1", out, error));
  CHECK(out.path == "/dev/hidraw4");  // an index counts in that order, as listMice shows it
  REQUIRE(selectMouse(mice, "/dev/input/event6", out, error));
  CHECK(out.path == "/dev/input/event6");  // asked for: the trackpoint
  // With no USB mouse in, a built-in one is the first.
  REQUIRE(selectMouse({laptop()[4], laptop()[0]}, "", out, error));
  CHECK(out.path == "/dev/hidraw0");  // the touchpad's I2C path sorts before the serio one
}

TEST_CASE("mouse selectors: first, index, path, VID:PID(:serial), @port, and clear errors", "[mouse][select]") {
  std::vector<MouseInfo> mice(2);
  mice[0].path = "/dev/hidraw1", mice[0].vendorId = 0x046d, mice[0].productId = 0xc077;
  mice[1].path = "/dev/hidraw4", mice[1].vendorId = 0x0458, mice[1].productId = 0x0138, mice[1].serial = "A1";
  MouseInfo out;
  std::string error;
  REQUIRE(selectMouse(mice, "", out, error));
  CHECK(out.path == "/dev/hidraw1");
  REQUIRE(selectMouse(mice, "1", out, error));
  CHECK(out.path == "/dev/hidraw4");
  REQUIRE(selectMouse(mice, "458:138", out, error));
  CHECK(out.path == "/dev/hidraw4");
  REQUIRE(selectMouse(mice, "0458:0138:A1", out, error));
  CHECK_FALSE(selectMouse(mice, "0458:0138:B2", out, error));
  CHECK(error.find("/dev/hidraw4") != std::string::npos);  // lists what there is
  CHECK_FALSE(selectMouse(mice, "2", out, error));
  CHECK_FALSE(selectMouse(mice, "mouse", out, error));
  // A node that is not a listed mouse (gone, or a keyboard's) is refused, not tried.
  CHECK_FALSE(selectMouse(mice, "/dev/hidraw9", out, error));
  CHECK(error.find("/dev/hidraw9 is not a mouse") != std::string::npos);
  CHECK_FALSE(selectMouse({}, "", out, error));
  CHECK(error.find("no mouse found") != std::string::npos);
  CHECK(reselector(mice[1]) == "0458:0138:A1");  // no port known: the ids and serial
  mice[1].busPath = "usb1/1-4/1-4:1.0";
  CHECK(reselector(mice[1]) == "0458:0138@usb1/1-4/1-4:1.0");
  REQUIRE(selectMouse(mice, "0458:0138@usb1/1-4/1-4:1.0", out, error));
  CHECK(out.path == "/dev/hidraw4");
  CHECK_FALSE(selectMouse(mice, "0458:0138@usb1/1-5/1-5:1.0", out, error));
}

TEST_CASE("bus paths keep the port and interface, not the numbers a plug-in hands out", "[mouse][select]") {
  // A Unifying receiver's paired mouse (hid-logitech-dj: a HID device under the receiver's
  // interface 2), its hidraw and its event node, before and after a replug.
  const std::string hid1 =
      "/sys/devices/pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.2/0003:046D:C52B.0003/0003:046D:4082.0004";
  const std::string hid2 =
      "/sys/devices/pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.2/0003:046D:C52B.0009/0003:046D:4082.000B";
  CHECK(stableBusPath(hid1) == "pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.2/0003:046D:C52B/0003:046D:4082");
  CHECK(stableBusPath(hid1) == stableBusPath(hid2));
  CHECK(stableBusPath(hid1 + "/input/input20") == stableBusPath(hid2 + "/input/input31"));
  CHECK(stableBusPath(hid1 + "/input/input20") ==
        "pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.2/0003:046D:C52B/0003:046D:4082/input");
  // Another port, another interface: another path.
  CHECK(stableBusPath("/sys/devices/pci0000:00/0000:00:14.0/usb1/1-3/1-3:1.0/0003:046D:C077.0001") !=
        stableBusPath("/sys/devices/pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.0/0003:046D:C077.0001"));
  CHECK(stableBusPath("/sys/devices/platform/i8042/serio1/input/input8") == "platform/i8042/serio1/input");
}

TEST_CASE("a re-open after a replug finds the mouse in its own port, not its twin in another", "[mouse][select]") {
  FakeMouseScript script;
  std::string error;
  REQUIRE(readHidRecorderFile(KF_HID_RECORDING, script.recording, error));
  script.kernelQueue = 4096;
  script.startS = 6.0;
  script.unplugAtS = 0.15;
  script.replugAtS = 0.25;
  script.replugPath = "/dev/hidraw8";  // a replug may give another node
  // The same make in a lower port (1-1, ours is in 1-2), listed and ordered before ours: with
  // the ids alone a re-open would take it.
  MouseInfo twin;
  twin.path = "/dev/hidraw2";
  twin.vendorId = static_cast<uint16_t>(script.recording.vendorId);
  twin.productId = static_cast<uint16_t>(script.recording.productId);
  twin.busPath = "pci0000:00/0000:00:14.0/usb1/1-1/1-1:1.0/0003:0458:0138";
  script.others = {twin};
  auto api = std::make_shared<FakeHidApi>(script);
  auto backend = HidapiMouseBackend::open(api, "/dev/hidraw7", error);
  REQUIRE(backend);
  REQUIRE(kf::test::waitFor([&] { return backend->state() != MouseState::kRunning; }));
  REQUIRE(backend->state() == MouseState::kUnplugged);
  api->timeline->sleepUntilSincePlug(0.26);
  backend->requestReopen();
  CHECK(kf::test::waitFor([&] { return backend->counters().reopens > 0; }));
  CHECK(backend->counters().reopens == 1);
  CHECK(backend->state() == MouseState::kRunning);
  CHECK(backend->info().path == "/dev/hidraw8");
  CHECK(backend->info().busPath == script.busPath);
}

TEST_CASE("a hidraw node's descriptor says whether it carries X/Y and whether it is a keyboard's too",
          "[mouse][select]") {
  HidRecording genius;
  std::string error;
  REQUIRE(readHidRecorderFile(KF_HID_RECORDING, genius, error));
  const DescriptorKind mouse = descriptorKind(genius.descriptor);
  CHECK(mouse.parsed);
  CHECK(mouse.hasXY);

  // A keyboard with a pointing stick on one interface: report 1 a boot keyboard's modifiers,
  // report 2 a mouse's three buttons and int8 X, Y (HID 1.11, appendix B and E).
  const std::vector<uint8_t> keyboardAndMouse = {
      0x05, 0x01, 0x09, 0x06, 0xA1, 0x01, 0x85, 0x01, 0x05, 0x07, 0x19, 0xE0, 0x29, 0xE7, 0x15, 0x00,
      0x25, 0x01, 0x75, 0x01, 0x95, 0x08, 0x81, 0x02, 0xC0, 0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x85,
      0x02, 0x09, 0x01, 0xA1, 0x00, 0x05, 0x09, 0x19, 0x01, 0x29, 0x03, 0x15, 0x00, 0x25, 0x01, 0x95,
      0x03, 0x75, 0x01, 0x81, 0x02, 0x95, 0x01, 0x75, 0x05, 0x81, 0x03, 0x05, 0x01, 0x09, 0x30, 0x09,
      0x31, 0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0xC0, 0xC0};
  const DescriptorKind both = descriptorKind(keyboardAndMouse);
  REQUIRE(both.parsed);
  CHECK(both.hasXY);
  CHECK(both.hasKeyboard);
  CHECK_FALSE(mouse.hasKeyboard);
  // The keyboard part alone: a keyboard, no X/Y.
  const DescriptorKind keyboard = descriptorKind({keyboardAndMouse.begin(), keyboardAndMouse.begin() + 25});
  CHECK(keyboard.hasKeyboard);
  CHECK_FALSE(keyboard.hasXY);
  CHECK_FALSE(descriptorKind({0x05, 0x01, 0xA1}).parsed);  // truncated: unknown

  // In the order: a keyboard's node with a mouse collection after a mouse's own.
  std::vector<MouseInfo> mice = {mouse_("/dev/hidraw1", "usb1/1-1/1-1:1.0", true),
                                 mouse_("/dev/hidraw6", "usb1/1-4/1-4:1.0", false)};
  orderMice(mice);
  CHECK(mice.front().path == "/dev/hidraw6");
}

TEST_CASE("finding a mouse again: its port first, elsewhere only with a serial, the one of its make",
          "[mouse][select]") {
  const MouseInfo ours = mouse("/dev/hidraw7", 0x0458, 0x0138, "usb1/1-2/1-2:1.0/0003:0458:0138", 0);
  const MouseInfo twin = mouse("/dev/hidraw2", 0x0458, 0x0138, "usb1/1-1/1-1:1.0/0003:0458:0138", 0);
  const MouseInfo other = mouse("/dev/hidraw3", 0x046d, 0xc077, "usb1/1-3/1-3:1.0/0003:046D:C077", 0);
  MouseInfo back = ours, out;
  back.path = "/dev/hidraw9";  // a new node in the same port
  std::string error;
  REQUIRE(findMouseAgain({twin, other, back}, ours, out, error));
  CHECK(out.path == "/dev/hidraw9");

  // Without a serial, the one of its make in another port may be its twin (open in another slot,
  // say) rather than it: not taken.
  CHECK_FALSE(findMouseAgain({twin, other}, ours, out, error));
  CHECK(error.find("no serial to tell it from a twin") != std::string::npos);

  // With a serial: back in another port (or a Bluetooth mouse reconnected: a new hci handle in
  // its path) it is found there.
  MouseInfo withSerial = ours;
  withSerial.serial = "A1B2";
  MouseInfo moved = withSerial;
  moved.path = "/dev/hidraw4", moved.busPath = "usb1/1-4/1-4:1.0/0003:0458:0138";
  REQUIRE(findMouseAgain({other, moved}, withSerial, out, error));
  CHECK(out.path == "/dev/hidraw4");
  // ... but with a twin of the same serial plugged in too, neither is taken for it.
  MouseInfo twinWithSerial = twin;
  twinWithSerial.serial = "A1B2";
  CHECK_FALSE(findMouseAgain({twinWithSerial, other, moved}, withSerial, out, error));
  CHECK(error.find("none in its port") != std::string::npos);
  // Another interface of the same mouse is not it.
  MouseInfo vendorInterface = moved;
  vendorInterface.interfaceNumber = 1;
  CHECK_FALSE(findMouseAgain({other, vendorInterface}, withSerial, out, error));
  CHECK(error.find("no mouse 0458:0138@usb1/1-2/1-2:1.0/0003:0458:0138 is plugged in") != std::string::npos);
  // A mouse whose port was not known is found by its make alone, when there is one.
  MouseInfo portUnknown = ours;
  portUnknown.busPath.clear();
  REQUIRE(findMouseAgain({other, twin}, portUnknown, out, error));
  CHECK(out.path == "/dev/hidraw2");
}
