// The real EvdevApi: Linux input event nodes. Enumeration reads sysfs (names, ids, the REL
// capability bits), which needs no permission on the nodes themselves.
// Off Linux, EvdevIoNotLinux.cpp.
#include <dirent.h>
#include <fcntl.h>
#include <linux/input.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <vector>

#include "mouse/MouseIo.hpp"
#include "mouse/MouseSelect.hpp"
#include "mouse/SysfsPath.hpp"

namespace kf {

namespace {

std::string readLine(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

uint16_t readHex(const std::string& path) {
  return static_cast<uint16_t>(std::strtoul(readLine(path).c_str(), nullptr, 16));
}

// A sysfs capability bitmap ("capabilities/rel", ".../key"): hex words of the kernel's long,
// most significant first; bit 0 of the last word is code 0. As udev's input_id reads it.
std::vector<unsigned long> readBitmap(const std::string& text) {
  std::istringstream words(text);
  std::vector<unsigned long> bits;
  std::string word;
  while (words >> word) bits.insert(bits.begin(), std::strtoul(word.c_str(), nullptr, 16));
  return bits;
}

bool hasBit(const std::vector<unsigned long>& bits, int code) {
  constexpr int kBitsPerWord = 8 * sizeof(unsigned long);
  const size_t word = static_cast<size_t>(code / kBitsPerWord);
  return word < bits.size() && (bits[word] >> (code % kBitsPerWord) & 1ul);
}

// Keys a keyboard has (udev's ID_INPUT_KEY: codes below BTN_MISC, and KEY_OK up to the
// trigger-happy buttons), not a mouse's buttons (BTN_MISC .. BTN_GEAR_UP). A node with both is
// never listed: reading it would read what is typed.
bool reportsKeys(const std::vector<unsigned long>& keys) {
  for (int code = KEY_ESC; code < BTN_MISC; ++code)
    if (hasBit(keys, code)) return true;
  for (int code = KEY_OK; code < BTN_TRIGGER_HAPPY; ++code)
    if (hasBit(keys, code)) return true;
  return false;
}

class RealEvdevHandle : public EvdevHandle {
 public:
  explicit RealEvdevHandle(int fd) : fd_(fd) {}
  ~RealEvdevHandle() override { ::close(fd_); }

  bool setMonotonicClock(std::string& error) override {
    int clockId = CLOCK_MONOTONIC;
    if (::ioctl(fd_, EVIOCSCLOCKID, &clockId) == 0) return true;
    error = std::string("EVIOCSCLOCKID: ") + std::strerror(errno);
    return false;
  }
  bool grab(bool on, std::string& error) override {
    if (::ioctl(fd_, EVIOCGRAB, on ? 1 : 0) == 0) return true;
    error = std::string("EVIOCGRAB: ") + std::strerror(errno);
    return false;
  }
  std::string name() override {
    char buffer[256] = {};
    if (::ioctl(fd_, EVIOCGNAME(sizeof(buffer) - 1), buffer) < 0) return {};
    return buffer;
  }
  bool id(uint16_t& vendorId, uint16_t& productId) override {
    input_id ids{};
    if (::ioctl(fd_, EVIOCGID, &ids) < 0) return false;
    vendorId = ids.vendor;
    productId = ids.product;
    return true;
  }
  bool buttonsDown(uint32_t& buttons) override {
    constexpr size_t kBitsPerWord = 8 * sizeof(unsigned long);
    unsigned long keys[(KEY_MAX + kBitsPerWord) / kBitsPerWord] = {};
    if (::ioctl(fd_, EVIOCGKEY(sizeof(keys)), keys) < 0) return false;
    buttons = 0;
    for (int code = BTN_LEFT; code <= BTN_TASK; ++code)
      if (keys[code / kBitsPerWord] >> (code % kBitsPerWord) & 1ul) buttons |= 1u << (code - BTN_LEFT);
    return true;
  }
  int read(EvdevEvent* out, int capacity, int timeoutMs, int* errnoOut) override {
    pollfd waitFor{fd_, POLLIN, 0};
    const int ready = ::poll(&waitFor, 1, timeoutMs);
    if (ready == 0 || (ready < 0 && errno == EINTR)) return 0;
    if (ready < 0 || (waitFor.revents & (POLLERR | POLLHUP | POLLNVAL))) {
      *errnoOut = ready < 0 ? errno : ENODEV;
      return -1;
    }
    input_event events[64];
    const int want = capacity < 64 ? capacity : 64;
    const ssize_t bytes = ::read(fd_, events, sizeof(input_event) * static_cast<size_t>(want));
    if (bytes < 0) {
      if (errno == EAGAIN || errno == EINTR) return 0;
      *errnoOut = errno;
      return -1;
    }
    const int count = static_cast<int>(bytes / static_cast<ssize_t>(sizeof(input_event)));
    for (int i = 0; i < count; ++i) {
      out[i].timeS = events[i].input_event_sec + events[i].input_event_usec * 1e-6;
      out[i].type = events[i].type;
      out[i].code = events[i].code;
      out[i].value = events[i].value;
    }
    return count;
  }

 private:
  int fd_;
};

class RealEvdevApi : public EvdevApi {
 public:
  explicit RealEvdevApi(std::string sysClassInput) : classDir_(std::move(sysClassInput)) {}

  bool enumerateMice(std::vector<MouseInfo>& out, std::string& error) override {
    out.clear();
    DIR* dir = ::opendir(classDir_.c_str());
    if (dir == nullptr) {
      error = classDir_ + ": " + std::strerror(errno);
      return errno == ENOENT;  // no input subsystem: no mice, not an error
    }
    while (const dirent* entry = ::readdir(dir)) {
      const std::string node = entry->d_name;
      if (node.rfind("event", 0) != 0) continue;
      const std::string sys = classDir_ + "/" + node + "/device/";
      const std::vector<unsigned long> rel = readBitmap(readLine(sys + "capabilities/rel"));
      if (!hasBit(rel, REL_X) || !hasBit(rel, REL_Y)) continue;
      if (reportsKeys(readBitmap(readLine(sys + "capabilities/key")))) continue;
      MouseInfo info;
      info.path = "/dev/input/" + node;
      info.product = readLine(sys + "name");
      info.vendorId = readHex(sys + "id/vendor");
      info.productId = readHex(sys + "id/product");
      info.serial = readLine(sys + "uniq");
      const uint16_t bus = readHex(sys + "id/bustype");
      info.external = bus == BUS_USB || bus == BUS_BLUETOOTH;  // a receiver's paired mouse is BUS_USB
      info.busPath = stableBusPath(resolveSysfs(classDir_ + "/" + node + "/device"));
      // The input device's parent is the HID device (for a USB or Bluetooth HID mouse, and a
      // receiver's paired one: hid-logitech-dj gives it a descriptor of its own).
      info.hidDescriptor = readBytes(sys + "device/report_descriptor");
      out.push_back(std::move(info));
    }
    ::closedir(dir);
    orderMice(out);
    return true;
  }

  std::unique_ptr<EvdevHandle> open(const std::string& path, std::string& error, OpenFailure& why) override {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
      const int code = errno;
      why = code == EACCES || code == EPERM    ? OpenFailure::kPermission
            : code == ENOENT || code == ENODEV ? OpenFailure::kNotFound
                                               : OpenFailure::kOther;
      error = why == OpenFailure::kPermission ? permissionFix(path) : path + ": " + std::strerror(code);
      return nullptr;
    }
    why = OpenFailure::kNone;
    return std::make_unique<RealEvdevHandle>(fd);
  }

 private:
  std::string classDir_;  // /sys/class/input
};

}  // namespace

std::shared_ptr<EvdevApi> realEvdevApi() {
  static std::shared_ptr<EvdevApi> api = std::make_shared<RealEvdevApi>("/sys/class/input");
  return api;
}

std::shared_ptr<EvdevApi> evdevApiReadingSysfsAt(const std::string& sysClassInput) {
  return std::make_shared<RealEvdevApi>(sysClassInput);
}

}  // namespace kf
