// The shipped udev rules (device/mouse/udev/70-kineticfriction.rules), read rule by rule and
// matched against the properties real nodes have (udevadm info of a mouse, a keyboard, a
// keyboard with a touchpad, a receiver's interfaces, the board): mice and the board are
// granted to the seat's user, nothing that reports keys ever is. This machine has no udevd
// (and Debian 12's udevadm has no "verify"), so the rules are parsed here, to the grammar of
// udev(7): KEY[{attr}] operator "value", comma-separated, one rule a line.
#include <fnmatch.h>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "board/BoardProtocol.hpp"

namespace {

struct Term {
  std::string key, attr, op, value;  // SUBSYSTEM "" == "input"; ENV ID_INPUT_MOUSE == "1"
};
using Rule = std::vector<Term>;

std::vector<Rule> readRules(std::vector<std::string>& malformed) {
  std::ifstream in(KF_UDEV_RULES);
  REQUIRE(in);
  // A term as udev(7) writes it; the value has no quote inside.
  const std::regex term(R"re(\s*([A-Z_]+)(\{([^}]+)\})?\s*(==|!=|\+=|-=|:=|=)\s*"([^"]*)"\s*)re");
  const std::vector<std::string> known = {"SUBSYSTEM", "SUBSYSTEMS", "KERNEL", "ENV",  "ATTR",
                                          "ATTRS",     "DRIVERS",    "TAG",    "MODE", "GROUP"};
  std::vector<Rule> rules;
  std::string line;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    Rule rule;
    size_t start = 0;
    bool ok = true;
    while (ok && start <= line.size()) {
      const size_t comma = line.find(',', start);
      const std::string text = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      std::smatch m;
      ok = std::regex_match(text, m, term) && std::find(known.begin(), known.end(), m[1].str()) != known.end();
      if (ok) rule.push_back({m[1], m[3], m[4], m[5]});
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (ok)
      rules.push_back(rule);
    else
      malformed.push_back(line);
  }
  return rules;
}

// A node as udev sees it: its own keys and the ATTRS of its parents.
struct Node {
  std::string name;
  std::map<std::string, std::string> props;  // SUBSYSTEM, KERNEL, ENV{..} as "ENV:..", ATTR(S){..} as "ATTR:.."
};

std::string lookup(const Node& node, const Term& t) {
  const std::string key = t.key == "ENV" ? "ENV:" + t.attr : t.key.rfind("ATTR", 0) == 0 ? "ATTR:" + t.attr : t.key;
  const auto found = node.props.find(key);
  return found == node.props.end() ? std::string() : found->second;
}

// What the rules grant the node: "uaccess" and/or a mode, "" when nothing.
std::string granted(const std::vector<Rule>& rules, const Node& node) {
  std::string grants;
  for (const Rule& rule : rules) {
    bool matches = true;
    for (const Term& t : rule) {
      const bool equal = fnmatch(t.value.c_str(), lookup(node, t).c_str(), 0) == 0;
      if ((t.op == "==" && !equal) || (t.op == "!=" && equal)) matches = false;
    }
    if (!matches) continue;
    for (const Term& t : rule) {
      if (t.key == "TAG" && t.value == "uaccess") grants += "uaccess ";
      if (t.key == "MODE") grants += "mode " + t.value + " ";
    }
  }
  return grants;
}

Node input(const std::string& name, bool mouse, bool key, bool keyboard) {
  Node n{name, {{"SUBSYSTEM", "input"}, {"KERNEL", "event7"}}};
  if (mouse) n.props["ENV:ID_INPUT_MOUSE"] = "1";
  if (key) n.props["ENV:ID_INPUT_KEY"] = "1";
  if (keyboard) n.props["ENV:ID_INPUT_KEYBOARD"] = "1";
  return n;
}

Node hidraw(const std::string& name, const char* subclass, const char* protocol) {
  return Node{name,
              {{"SUBSYSTEM", "hidraw"},
               {"KERNEL", "hidraw3"},
               {"ATTR:bInterfaceClass", "03"},
               {"ATTR:bInterfaceSubClass", subclass},
               {"ATTR:bInterfaceProtocol", protocol}}};
}

Node usbDevice(const std::string& name, uint16_t vendor, uint16_t product) {
  char ids[2][8];
  std::snprintf(ids[0], sizeof ids[0], "%04x", vendor);
  std::snprintf(ids[1], sizeof ids[1], "%04x", product);
  return Node{
      name,
      {{"SUBSYSTEM", "usb"}, {"ENV:DEVTYPE", "usb_device"}, {"ATTR:idVendor", ids[0]}, {"ATTR:idProduct", ids[1]}}};
}

}  // namespace

TEST_CASE("udev rules: every line parses, mice and the board are granted, no node that reports keys is",
          "[mouse][udev]") {
  std::vector<std::string> malformed;
  const std::vector<Rule> rules = readRules(malformed);
  CHECK(malformed.empty());
  REQUIRE(rules.size() == 3);

  // Granted: a USB mouse's event node, a receiver's paired mouse (its own node, a mouse to
  // input_id), a boot mouse interface's hidraw, the board with the ids its driver looks for.
  CHECK(granted(rules, input("mouse event node", true, false, false)) == "uaccess ");
  CHECK(granted(rules, hidraw("boot mouse hidraw", "01", "02")) == "uaccess ");
  CHECK(granted(rules, usbDevice("board", kf::board::kVendorId, kf::board::kProductId)) == "mode 0660 uaccess ");

  // Never granted: keyboards, nodes that report both pointer and keys (a keyboard with a
  // touchpad, a gaming mouse's macro keys), a receiver's keyboard and vendor interfaces, other
  // USB devices (another product on the test vendor id).
  for (const Node& node :
       {input("keyboard event node", false, true, true), input("keyboard with a touchpad, one node", true, true, true),
        input("mouse with keys (ID_INPUT_KEY only)", true, true, false),
        input("receiver keyboard child", false, true, true),
        hidraw("boot keyboard hidraw (receiver interface 0)", "01", "01"),
        hidraw("receiver vendor interface (hid-logitech-dj children)", "00", "00"),
        usbDevice("another test-vid device", kf::board::kVendorId, 0x0002), usbDevice("a USB hub", 0x1d6b, 0x0002)}) {
    INFO(node.name);
    CHECK(granted(rules, node).empty());
  }
}
