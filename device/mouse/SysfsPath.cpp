#include "mouse/SysfsPath.hpp"

#include <cctype>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace kf {

namespace {

bool isDigits(const std::string& text, size_t from) {
  if (from >= text.size()) return false;
  for (size_t i = from; i < text.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(text[i]))) return false;
  return true;
}

bool isHex(const std::string& text, size_t from, size_t count) {
  if (from + count > text.size()) return false;
  for (size_t i = from; i < from + count; ++i)
    if (!std::isxdigit(static_cast<unsigned char>(text[i]))) return false;
  return true;
}

// The kernel names a HID device "BBBB:VVVV:PPPP.NNNN" (drivers/hid/hid-core.c, hid_add_device).
bool isHidDeviceName(const std::string& part) {
  return part.size() == 19 && isHex(part, 0, 4) && part[4] == ':' && isHex(part, 5, 4) && part[9] == ':' &&
         isHex(part, 10, 4) && part[14] == '.' && isHex(part, 15, 4);
}

}  // namespace

std::string stableBusPath(const std::string& sysfsPath) {
  std::string path = sysfsPath;
  const std::string devices = "/sys/devices/";
  if (const size_t at = path.find(devices); at != std::string::npos) path = path.substr(at + devices.size());
  std::istringstream parts(path);
  std::string part, out;
  while (std::getline(parts, part, '/')) {
    if (part.empty()) continue;
    if (part.rfind("input", 0) == 0 && isDigits(part, 5)) continue;
    if (isHidDeviceName(part)) part.resize(14);
    out += out.empty() ? part : "/" + part;
  }
  return out;
}

std::string resolveSysfs(const std::string& link) {
  std::error_code error;
  const std::filesystem::path resolved = std::filesystem::canonical(link, error);  // realpath(3)
  return error ? std::string() : resolved.string();
}

}  // namespace kf
