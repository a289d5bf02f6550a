// The evdev backend's enumeration over a copy of sysfs (/sys/class/input and the devices its
// links point at) with the nodes a laptop with a Unifying receiver has: the receiver's paired
// mouse and keyboard (hid-logitech-dj children), a keyboard with a touchpad on one node, the
// built-in keyboard and trackpoint (PS/2). Only mice are listed, never a node that reports keys,
// and the USB mouse comes before the trackpoint.
#include <unistd.h>

#include <linux/input.h>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <vector>

#include "mouse/MouseIo.hpp"
#include "mouse/MouseSelect.hpp"

using namespace kf;
namespace fs = std::filesystem;

namespace {

// sysfs's bitmap text of these codes: 64-bit words, most significant first (as the kernel
// prints them on a 64-bit machine and udev's input_id reads them).
std::string bitmap(std::initializer_list<int> codes) {
  unsigned long words[KEY_MAX / 64 + 1] = {};
  int top = 0;
  for (int code : codes) {
    words[code / 64] |= 1ul << (code % 64);
    top = std::max(top, code / 64);
  }
  std::string out;
  char word[24];
  for (int i = top; i >= 0; --i) {
    std::snprintf(word, sizeof word, i == top ? "%lx" : " %lx", words[i]);
    out += word;
  }
  return out;
}

struct FakeSysfs {
  fs::path root = fs::path(KF_TEST_OUTPUT_DIR) / "fake-sysfs";
  FakeSysfs() {
    fs::remove_all(root);
    fs::create_directories(root / "sys/class/input");
  }
  ~FakeSysfs() { fs::remove_all(root); }
  // The HID device's report descriptor (a HID device has one; a PS/2 mouse's parent does not).
  void addDescriptor(const std::string& devicePath, const std::vector<uint8_t>& bytes) {
    std::ofstream(root / "sys/devices" / devicePath / "report_descriptor", std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  std::string classDir() const { return (root / "sys/class/input").string(); }

  // An input device at devices/<devicePath>/input/inputN with its event node.
  void add(const std::string& event, const std::string& devicePath, int inputNumber, uint16_t bus, uint16_t vid,
           uint16_t pid, const std::string& name, std::initializer_list<int> rel, std::initializer_list<int> keys) {
    const fs::path input = root / "sys/devices" / devicePath / "input" / ("input" + std::to_string(inputNumber));
    fs::create_directories(input / "capabilities");
    fs::create_directories(input / "id");
    fs::create_directories(input / event);
    auto write = [](const fs::path& file, const std::string& text) { std::ofstream(file) << text << "\n"; };
    auto hex = [](uint16_t v) {
      char text[8];
      std::snprintf(text, sizeof text, "%04x", v);
      return std::string(text);
    };
    write(input / "capabilities/rel", bitmap(rel));
    write(input / "capabilities/key", keys.size() ? bitmap(keys) : "0");
    write(input / "name", name);
    write(input / "uniq", "");
    write(input / "id/bustype", hex(bus));
    write(input / "id/vendor", hex(vid));
    write(input / "id/product", hex(pid));
    fs::create_directory_symlink(input, input / event / "device");
    fs::create_directory_symlink(root / "sys/devices" / devicePath, input / "device");  // its parent, the HID device
    fs::create_directory_symlink(input / event, root / "sys/class/input" / event);
  }
};

}  // namespace

TEST_CASE("evdev enumeration lists mice only, never a node that reports keys, USB before built in",
          "[mouse][evdev][select]") {
  FakeSysfs sysfs;
  // The USB controller at 00:1d.0 sorts after the I2C controller at 00:15.0.
  const std::string receiver = "pci0000:00/0000:00:1d.0/usb2/2-1/2-1:1.2/0003:046D:C52B.0003";
  // Listed in an order readdir may give: the built-in ones first.
  sysfs.add("event3", "platform/i8042/serio0", 3, BUS_I8042, 0x0001, 0x0001, "AT Translated Set 2 keyboard", {},
            {KEY_ESC, KEY_A, KEY_Z, KEY_ENTER});
  sysfs.add("event6", "platform/i8042/serio1/serio2", 6, BUS_I8042, 0x0002, 0x000a, "TPPS/2 IBM TrackPoint",
            {REL_X, REL_Y}, {BTN_LEFT, BTN_RIGHT, BTN_MIDDLE});
  sysfs.add("event5", "pci0000:00/0000:00:15.0/i2c_designware.0/i2c-0/i2c-ELAN0001:00/0018:04F3:3140.0001", 5, BUS_I2C,
            0x04f3, 0x3140, "ELAN0001:00 04F3:3140 Mouse", {REL_X, REL_Y}, {BTN_LEFT, BTN_RIGHT});
  sysfs.add("event20", receiver + "/0003:046D:4082.0004", 20, BUS_USB, 0x046d, 0x4082, "Logitech M705",
            {REL_X, REL_Y, REL_WHEEL, REL_HWHEEL}, {BTN_LEFT, BTN_RIGHT, BTN_MIDDLE, BTN_SIDE, BTN_EXTRA});
  sysfs.add("event21", receiver + "/0003:046D:4023.0005", 21, BUS_USB, 0x046d, 0x4023, "Logitech K400", {REL_X, REL_Y},
            {KEY_ESC, KEY_A, BTN_LEFT});  // a keyboard with a touchpad, one node
  sysfs.add("event22", receiver + "/0003:046D:2010.0006", 22, BUS_USB, 0x046d, 0x2010, "Logitech K270", {},
            {KEY_ESC, KEY_A, KEY_VOLUMEUP});
  sysfs.add("event23", "pci0000:00/0000:00:14.0/usb1/1-3/1-3:1.0/0003:1532:0084.0007", 23, BUS_USB, 0x1532, 0x0084,
            "Razer Mouse Keyboard", {REL_X, REL_Y}, {BTN_LEFT, KEY_OK});  // macro keys on the mouse's node

  // The paired mouse's HID device (hid-logitech-dj's child) has a descriptor; its bytes here
  // stand for any (the enumeration passes them on, the backend parses them).
  const std::vector<uint8_t> m705Descriptor = {0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x00, 0xff, 0xc0};
  sysfs.addDescriptor(receiver + "/0003:046D:4082.0004", m705Descriptor);

  std::vector<MouseInfo> mice;
  std::string error;
  REQUIRE(evdevApiReadingSysfsAt(sysfs.classDir())->enumerateMice(mice, error));
  REQUIRE(mice.size() == 3);
  CHECK(mice[0].path == "/dev/input/event20");  // the receiver's mouse, the first
  CHECK(mice[0].external);
  CHECK(mice[0].vendorId == 0x046d);
  CHECK(mice[0].busPath == "pci0000:00/0000:00:1d.0/usb2/2-1/2-1:1.2/0003:046D:C52B/0003:046D:4082/input");
  CHECK(mice[1].path == "/dev/input/event5");  // the touchpad and the trackpoint after it
  CHECK_FALSE(mice[1].external);
  CHECK(mice[2].path == "/dev/input/event6");
  CHECK_FALSE(mice[2].external);
  // The descriptor under the node, bytes as they are (the saturation limits come from it); none
  // for the PS/2 trackpoint.
  CHECK(mice[0].hidDescriptor == m705Descriptor);
  CHECK(mice[2].hidDescriptor.empty());
  // A keyboard's node, asked for by path, is refused before any open.
  MouseInfo out;
  CHECK_FALSE(selectMouse(mice, "/dev/input/event21", out, error));
  CHECK(error.find("not a mouse") != std::string::npos);
}
