#include "board/gadget/GadgetConfigfs.hpp"

#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "board/BoardProtocol.hpp"

namespace kf::board::gadget {

namespace {

constexpr const char* kConfigfs = "/sys/kernel/config";
constexpr const char* kFunctionFsRoot = "/dev/ffs";  // the mount points: /dev/ffs/<name>
constexpr unsigned kMaxPowerMa = 100;                // the logic only: the coil has its own supply

bool writeFile(const std::string& path, const std::string& text, std::string& error) {
  std::ofstream out(path);
  out << text;
  out.flush();
  if (!out) {
    error = "cannot write '" + text + "' to " + path + ": " + std::strerror(errno);
    return false;
  }
  return true;
}

bool makeDir(const std::string& path, std::string& error) {
  if (::mkdir(path.c_str(), 0755) == 0 || errno == EEXIST) return true;
  error = "cannot make " + path + ": " + std::strerror(errno);
  return false;
}

std::string hex4(unsigned value) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%04x", value);
  return text;
}

}  // namespace

GadgetConfigfs::GadgetConfigfs(GadgetIdentity identity) : identity_(std::move(identity)) {}

GadgetConfigfs::~GadgetConfigfs() { remove(); }

std::string GadgetConfigfs::gadgetDir() const { return std::string(kConfigfs) + "/usb_gadget/" + identity_.name; }

std::string GadgetConfigfs::functionFsDir() const { return std::string(kFunctionFsRoot) + "/" + identity_.name; }

bool GadgetConfigfs::create(std::string& error) {
  if (!std::filesystem::exists(std::string(kConfigfs) + "/usb_gadget")) {
    if (::mount("none", kConfigfs, "configfs", 0, nullptr) != 0 && errno != EBUSY) {
      error = std::string("cannot mount configfs: ") + std::strerror(errno);
      return false;
    }
    if (!std::filesystem::exists(std::string(kConfigfs) + "/usb_gadget")) {
      error = "no /sys/kernel/config/usb_gadget: load libcomposite (modprobe libcomposite)";
      return false;
    }
  }
  const std::string g = gadgetDir();
  const std::string function = g + "/functions/ffs." + identity_.name;
  if (!makeDir(g, error)) return false;
  created_ = true;
  if (!writeFile(g + "/idVendor", hex4(kVendorId), error) || !writeFile(g + "/idProduct", hex4(kProductId), error) ||
      !writeFile(g + "/bcdDevice", hex4(identity_.bcdDevice), error) || !writeFile(g + "/bcdUSB", "0x0200", error) ||
      !makeDir(g + "/strings/0x409", error) ||
      !writeFile(g + "/strings/0x409/manufacturer", identity_.manufacturer, error) ||
      !writeFile(g + "/strings/0x409/product", identity_.product, error) ||
      !writeFile(g + "/strings/0x409/serialnumber", identity_.serial, error) || !makeDir(g + "/configs/c.1", error) ||
      !writeFile(g + "/configs/c.1/MaxPower", std::to_string(kMaxPowerMa), error))
    return false;
  if (::mkdir(function.c_str(), 0755) != 0 && errno != EEXIST) {
    error = "cannot make the FunctionFS function " + function + ": " + std::strerror(errno) +
            " (load usb_f_fs: modprobe usb_f_fs)";
    return false;
  }
  const std::string link = g + "/configs/c.1/ffs." + identity_.name;
  if (::symlink(function.c_str(), link.c_str()) != 0 && errno != EEXIST) {
    error = "cannot put the function in the configuration: " + std::string(std::strerror(errno));
    return false;
  }
  std::error_code ignored;
  std::filesystem::create_directories(functionFsDir(), ignored);
  if (::mount(identity_.name.c_str(), functionFsDir().c_str(), "functionfs", 0, nullptr) != 0) {
    error = "cannot mount FunctionFS at " + functionFsDir() + ": " + std::strerror(errno);
    return false;
  }
  mounted_ = true;
  return true;
}

bool GadgetConfigfs::bind(const std::string& udc, std::string& error) {
  std::string chosen = udc;
  if (chosen.empty()) {
    if (std::filesystem::exists("/sys/class/udc"))
      for (const auto& entry : std::filesystem::directory_iterator("/sys/class/udc")) {
        chosen = entry.path().filename().string();
        break;
      }
    if (chosen.empty()) {
      error = "no USB device controller in /sys/class/udc (a board's device port, or dummy_hcd)";
      return false;
    }
  }
  if (!writeFile(gadgetDir() + "/UDC", chosen, error)) return false;
  udc_ = chosen;
  return true;
}

void GadgetConfigfs::unbind() {
  if (udc_.empty()) return;
  std::string ignored;
  writeFile(gadgetDir() + "/UDC", "\n", ignored);
  udc_.clear();
}

void GadgetConfigfs::remove() {
  unbind();
  if (mounted_) ::umount(functionFsDir().c_str());
  mounted_ = false;
  if (!created_) return;
  const std::string g = gadgetDir();
  // configfs: links and folders go in the reverse order of their making; files go with them.
  ::unlink((g + "/configs/c.1/ffs." + identity_.name).c_str());
  ::rmdir((g + "/functions/ffs." + identity_.name).c_str());
  ::rmdir((g + "/configs/c.1").c_str());
  ::rmdir((g + "/strings/0x409").c_str());
  ::rmdir(g.c_str());
  created_ = false;
}

}  // namespace kf::board::gadget
