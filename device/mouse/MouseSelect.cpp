#include "mouse/MouseSelect.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <tuple>

namespace kf {

namespace {

bool allDigits(const std::string& text) {
  if (text.empty()) return false;
  for (char c : text)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  return true;
}

bool parseSelectorHexId(const std::string& text, uint16_t& out) {
  if (text.empty() || text.size() > 4) return false;
  char* end = nullptr;
  const unsigned long value = std::strtoul(text.c_str(), &end, 16);
  if (*end != '\0') return false;
  out = static_cast<uint16_t>(value);
  return true;
}

std::string listOf(const std::vector<MouseInfo>& mice) {
  if (mice.empty()) return " (no mouse found)";
  std::string out;
  for (size_t i = 0; i < mice.size(); ++i) out += "\n  " + describeMouse(static_cast<int>(i), mice[i]);
  return out;
}

}  // namespace

void orderMice(std::vector<MouseInfo>& mice) {
  auto key = [](const MouseInfo& m) {
    // An unknown bus path sorts after every known one.
    return std::make_tuple(!m.external, !m.hasXY, m.alsoKeyboard, m.busPath.empty(), m.busPath, m.interfaceNumber,
                           m.path);
  };
  std::stable_sort(mice.begin(), mice.end(), [&](const MouseInfo& a, const MouseInfo& b) { return key(a) < key(b); });
}

bool selectMouse(std::vector<MouseInfo> mice, const std::string& which, MouseInfo& out, std::string& error) {
  orderMice(mice);
  if (which.empty() || which == "first") {
    if (mice.empty()) {
      error = "no mouse found: plug one in (and see the udev rule if it is there but not listed)";
      return false;
    }
    out = mice.front();
    return true;
  }
  if (allDigits(which)) {
    const size_t index = std::strtoul(which.c_str(), nullptr, 10);
    if (index < mice.size()) {
      out = mice[index];
      return true;
    }
    error = "no mouse " + which + "; there are:" + listOf(mice);
    return false;
  }
  if (which[0] == '/') {
    for (const MouseInfo& info : mice)
      if (info.path == which) {
        out = info;
        return true;
      }
    // Not a mouse this backend lists: not there, or a keyboard's node, which is never opened.
    error = which + " is not a mouse this backend lists; there are:" + listOf(mice);
    return false;
  }
  const size_t at = which.find('@');
  const std::string port = at == std::string::npos ? std::string() : which.substr(at + 1);
  const std::string ids = which.substr(0, at);
  const size_t colon = ids.find(':');
  const size_t second = colon == std::string::npos ? std::string::npos : ids.find(':', colon + 1);
  uint16_t vendorId = 0, productId = 0;
  if (colon == std::string::npos || !parseSelectorHexId(ids.substr(0, colon), vendorId) ||
      !parseSelectorHexId(ids.substr(colon + 1, second == std::string::npos ? std::string::npos : second - colon - 1),
                          productId)) {
    error = "cannot read the mouse selector '" + which +
            "': give an index, a device path, or VVVV:PPPP[:serial] or VVVV:PPPP@port in hex";
    return false;
  }
  const std::string serial = second == std::string::npos ? std::string() : ids.substr(second + 1);
  for (const MouseInfo& info : mice)
    if (info.vendorId == vendorId && info.productId == productId && (serial.empty() || info.serial == serial) &&
        (port.empty() || info.busPath == port)) {
      out = info;
      return true;
    }
  error = "no mouse " + which + "; there are:" + listOf(mice);
  return false;
}

bool findMouseAgain(std::vector<MouseInfo> mice, const MouseInfo& previous, MouseInfo& out, std::string& error) {
  orderMice(mice);
  std::vector<const MouseInfo*> sameMake;
  for (const MouseInfo& m : mice) {
    const bool same = previous.vendorId == 0 && previous.productId == 0
                          ? m.path == previous.path  // no ids known: its node
                          : m.vendorId == previous.vendorId && m.productId == previous.productId &&
                                m.serial == previous.serial && m.interfaceNumber == previous.interfaceNumber;
    if (!same) continue;
    if (!previous.busPath.empty() && m.busPath == previous.busPath) {
      out = m;
      return true;
    }
    sameMake.push_back(&m);
  }
  // Elsewhere only a mouse with a serial is known to be the same one: two mice of one make
  // without serials (most) are told apart by their port alone, and the twin of an unplugged
  // mouse, open in another slot or not, is not it.
  const bool knownElsewhere = previous.busPath.empty() || !previous.serial.empty();
  if (sameMake.size() == 1 && knownElsewhere) {
    out = *sameMake.front();
    return true;
  }
  error = sameMake.empty() ? "no mouse " + reselector(previous) + " is plugged in; there are:" + listOf(mice)
          : sameMake.size() == 1
              ? "a mouse like " + reselector(previous) +
                    " is plugged in elsewhere, but it has no serial to tell it from a twin: plug it back where "
                    "it was, or open it again; there are:" +
                    listOf(mice)
              : std::to_string(sameMake.size()) + " mice like " + reselector(previous) +
                    " are plugged in, none in its port: plug it back where it was; there are:" + listOf(mice);
  return false;
}

std::string reselector(const MouseInfo& info) {
  if (info.vendorId == 0 && info.productId == 0) return info.path;
  char ids[16];
  std::snprintf(ids, sizeof(ids), "%04x:%04x", info.vendorId, info.productId);
  // Two mice of one make (the same ids, often no serial) are told apart by their port.
  if (!info.busPath.empty()) return std::string(ids) + "@" + info.busPath;
  return info.serial.empty() ? std::string(ids) : std::string(ids) + ":" + info.serial;
}

std::string describeMouse(int index, const MouseInfo& info) {
  char ids[16];
  std::snprintf(ids, sizeof(ids), "%04x:%04x", info.vendorId, info.productId);
  std::string out = std::to_string(index) + ": " + info.path + " " + ids + " ";
  out += info.manufacturer.empty() ? info.product : info.manufacturer + " " + info.product;
  if (!info.serial.empty()) out += " (serial " + info.serial + ")";
  if (info.interfaceNumber >= 0) out += " interface " + std::to_string(info.interfaceNumber);
  if (!info.external) out += " (built in)";
  if (!info.hasXY) out += " (no X/Y in its reports)";
  if (info.alsoKeyboard) out += " (also a keyboard)";
  if (!info.busPath.empty()) out += " at " + info.busPath;
  return out;
}

}  // namespace kf
