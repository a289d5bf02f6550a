// The real HidApi: hidapi over hidraw. Report descriptors: hid_get_report_descriptor where
// hidapi has it (0.14+); on Linux with older hidapi (Debian's 0.13) from sysfs, or the hidraw
// node's HIDIOCGRDESC ioctl when sysfs is not there. Enumeration reads the descriptor from
// sysfs too (anyone may), to put the interfaces whose reports carry X and Y first.
#include <hidapi/hidapi.h>

#include <cerrno>
#include <cstring>
#include <cwchar>
#include <fstream>
#include <iterator>
#include <mutex>

#include "mouse/DescriptorKind.hpp"
#include "mouse/MouseIo.hpp"
#include "mouse/MouseSelect.hpp"
#include "mouse/SysfsPath.hpp"

#ifdef __linux__
#include <fcntl.h>
#include <linux/hidraw.h>
#include <sys/ioctl.h>
#include <unistd.h>
#endif

namespace kf {

namespace {

std::string narrow(const wchar_t* text) {
  std::string out;
  if (text == nullptr) return out;
  for (; *text != L'\0'; ++text) out.push_back(*text < 128 ? static_cast<char>(*text) : '?');
  return out;
}

OpenFailure classifyOpenFailure(const std::string& path) {
#ifdef __linux__
  if (::access(path.c_str(), R_OK | W_OK) == 0) return OpenFailure::kOther;
  if (errno == EACCES || errno == EPERM) return OpenFailure::kPermission;
  if (errno == ENOENT) return OpenFailure::kNotFound;
#else
  (void)path;
#endif
  return OpenFailure::kOther;
}

#ifdef __linux__
std::string hidrawNode(const std::string& path) { return path.substr(path.find_last_of('/') + 1); }

// /dev/hidrawN -> /sys/class/hidraw/hidrawN/device/report_descriptor (readable by anyone).
bool readSysfsDescriptor(const std::string& path, std::vector<uint8_t>& out) {
  std::ifstream in("/sys/class/hidraw/" + hidrawNode(path) + "/device/report_descriptor", std::ios::binary);
  if (!in) return false;
  out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !out.empty();
}

#if HID_API_VERSION < HID_API_MAKE_VERSION(0, 14, 0)
bool readIoctlDescriptor(const std::string& path, std::vector<uint8_t>& out, std::string& error) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error = path + ": " + std::strerror(errno);
    return false;
  }
  int size = 0;
  hidraw_report_descriptor descriptor{};
  bool ok = ::ioctl(fd, HIDIOCGRDESCSIZE, &size) == 0 && size > 0 && size <= HID_MAX_DESCRIPTOR_SIZE;
  if (ok) {
    descriptor.size = static_cast<uint32_t>(size);
    ok = ::ioctl(fd, HIDIOCGRDESC, &descriptor) == 0;
  }
  if (!ok) error = path + ": HIDIOCGRDESC failed: " + std::strerror(errno);
  ::close(fd);
  if (ok) out.assign(descriptor.value, descriptor.value + descriptor.size);
  return ok;
}
#endif
#endif

class RealHidHandle : public HidHandle {
 public:
  RealHidHandle(hid_device* device, std::string path) : device_(device), path_(std::move(path)) {}
  ~RealHidHandle() override { hid_close(device_); }

  int readTimeout(uint8_t* buffer, size_t capacity, int timeoutMs) override {
    return hid_read_timeout(device_, buffer, capacity, timeoutMs);
  }
  std::string lastError() override { return narrow(hid_error(device_)); }

  bool reportDescriptor(std::vector<uint8_t>& out, std::string& error) override {
#if HID_API_VERSION >= HID_API_MAKE_VERSION(0, 14, 0)
    out.resize(HID_API_MAX_REPORT_DESCRIPTOR_SIZE);
    const int size = hid_get_report_descriptor(device_, out.data(), out.size());
    if (size <= 0) {
      error = path_ + ": no report descriptor: " + lastError();
      return false;
    }
    out.resize(static_cast<size_t>(size));
    return true;
#elif defined(__linux__)
    if (readSysfsDescriptor(path_, out)) return true;
    return readIoctlDescriptor(path_, out, error);
#else
    error = "this hidapi cannot read report descriptors (0.14 or newer needed)";
    (void)out;
    return false;
#endif
  }

 private:
  hid_device* device_;
  std::string path_;
};

class RealHidApi : public HidApi {
 public:
  bool enumerateMice(std::vector<MouseInfo>& out, std::string& error) override {
    out.clear();
    std::lock_guard<std::mutex> lock(globalState_);
    if (!init(error)) return false;
    hid_device_info* list = hid_enumerate(0, 0);
    for (hid_device_info* d = list; d != nullptr; d = d->next) {
      if (d->usage_page != 0x01 || d->usage != 0x02) continue;
      MouseInfo info;
      info.path = d->path ? d->path : "";
      info.vendorId = d->vendor_id;
      info.productId = d->product_id;
      info.serial = narrow(d->serial_number);
      info.manufacturer = narrow(d->manufacturer_string);
      info.product = narrow(d->product_string);
      info.interfaceNumber = d->interface_number;
      info.usagePage = d->usage_page;
      info.usage = d->usage;
      info.external = d->bus_type == HID_API_BUS_USB || d->bus_type == HID_API_BUS_BLUETOOTH;
#ifdef __linux__
      info.busPath = stableBusPath(resolveSysfs("/sys/class/hidraw/" + hidrawNode(info.path) + "/device"));
      std::vector<uint8_t> descriptor;
      const DescriptorKind kind =
          readSysfsDescriptor(info.path, descriptor) ? descriptorKind(descriptor) : DescriptorKind{};
      info.hasXY = !kind.parsed || kind.hasXY;  // unknown is not held against it
      info.alsoKeyboard = kind.hasKeyboard;
#endif
      out.push_back(std::move(info));
    }
    hid_free_enumeration(list);
    orderMice(out);
    return true;
  }

  std::unique_ptr<HidHandle> openPath(const std::string& path, std::string& error, OpenFailure& why) override {
    why = OpenFailure::kNone;
    std::lock_guard<std::mutex> lock(globalState_);
    if (!init(error)) {
      why = OpenFailure::kOther;
      return nullptr;
    }
    hid_device* device = hid_open_path(path.c_str());
    if (device == nullptr) {
      why = classifyOpenFailure(path);
      // hid_error(NULL) is hidapi's one global string, replaced by every failing call: read
      // under the lock, before another thread's open or enumeration frees it.
      error = why == OpenFailure::kPermission ? permissionFix(path) : path + ": " + narrow(hid_error(nullptr));
      return nullptr;
    }
    return std::make_unique<RealHidHandle>(device, path);
  }

 private:
  // hidapi keeps global state (the init flag, the global error string that hid_enumerate and
  // hid_open_path replace and free) with no lock of its own: the reader threads' re-opens and
  // the commands' listing and opening take turns here. Reads, closes and a device's own error
  // string touch only that device and its reader thread.
  std::mutex globalState_;

  bool init(std::string& error) {
    std::call_once(initOnce_, [this] { initOk_ = hid_init() == 0; });
    if (!initOk_) error = "hid_init failed: " + narrow(hid_error(nullptr));
    return initOk_;
  }
  std::once_flag initOnce_;
  bool initOk_ = false;
};

}  // namespace

std::shared_ptr<HidApi> realHidApi() {
  static std::shared_ptr<HidApi> api = std::make_shared<RealHidApi>();
  return api;
}

}  // namespace kf
