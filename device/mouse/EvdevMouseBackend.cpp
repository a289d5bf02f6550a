#include "mouse/EvdevMouseBackend.hpp"

#include <cerrno>
#include <cstring>

#include "hid/HidMouseDecoder.hpp"
#include "hid/HidReportDescriptor.hpp"
#include "mouse/MouseSelect.hpp"

namespace kf {

namespace {
// From linux/input-event-codes.h (kept here so the backend builds and is tested anywhere).
constexpr uint16_t kEvSyn = 0x00, kEvKey = 0x01, kEvRel = 0x02;
constexpr uint16_t kSynReport = 0, kSynDropped = 3;
constexpr uint16_t kRelX = 0x00, kRelY = 0x01;
constexpr uint16_t kBtnLeft = 0x110, kBtnTask = 0x117;  // BTN_LEFT .. BTN_TASK: buttons 1..8

// evdev passes the HID field's value on, clamped to the field's logical range (hid-input
// does), but says nothing of that range: it comes from the HID device's report descriptor.
EvdevMouseBackend::AxisLimits limitsOf(const std::vector<uint8_t>& descriptor) {
  EvdevMouseBackend::AxisLimits limits;
  HidReportDescriptor parsed;
  HidMouseDecoder decoder;
  std::string error;
  if (descriptor.empty() || !parseHidReportDescriptor(descriptor.data(), descriptor.size(), parsed, error) ||
      !decoder.build(parsed, error))
    return limits;
  limits.fromDescriptor = decoder.axisRange(limits.xLowest, limits.xHighest, limits.yLowest, limits.yHighest);
  return limits;
}
}  // namespace

bool EvdevMouseBackend::AxisLimits::atLimit(bool isX, int32_t value) const {
  if (value == 0) return false;
  if (!fromDescriptor)  // no descriptor (PS/2, a trackpoint): a guess from the usual field widths
    return value == 127 || value == -127 || value == -128 || value == 32767 || value == -32767 || value == -32768;
  return isX ? value <= xLowest || value >= xHighest : value <= yLowest || value >= yHighest;
}

std::unique_ptr<EvdevMouseBackend> EvdevMouseBackend::open(std::shared_ptr<EvdevApi> api, const std::string& which,
                                                           bool grab, std::string& error, OpenFailure* why,
                                                           const ThreadRequest& thread) {
  if (why) *why = OpenFailure::kOther;
  std::vector<MouseInfo> mice;
  if (!api->enumerateMice(mice, error)) return nullptr;
  std::unique_ptr<EvdevMouseBackend> backend(new EvdevMouseBackend(std::move(api), grab));
  if (!backend->openSelected(mice, which, error, why, thread)) return nullptr;
  return backend;
}

bool EvdevMouseBackend::openInfo(const MouseInfo& info, std::string& error, OpenFailure& why) {
  std::unique_ptr<EvdevHandle> handle = api_->open(info.path, error, why);
  if (!handle) return false;
  std::string clockError;
  kernelTimestamps_ = handle->setMonotonicClock(clockError);
  if (!kernelTimestamps_.load()) setError(info.path + ": " + clockError + "; using arrival times instead");
  if (grab_ && !handle->grab(true, error)) {
    error = info.path + ": " + error + " (another program holds the mouse?)";
    why = OpenFailure::kOther;
    return false;
  }
  current_ = info;
  limits_ = limitsOf(info.hidDescriptor);
  const std::string name = handle->name();
  if (!name.empty()) current_.product = name;
  handle->id(current_.vendorId, current_.productId);
  publishInfo(current_);
  handle_ = std::move(handle);
  dx_ = dy_ = 0;
  packetHasData_ = packetSaturated_ = dropping_ = false;
  buttons_ = 0;
  handle_->buttonsDown(buttons_);  // held through a replug, or down at the open: the kernel knows
  return true;
}

bool EvdevMouseBackend::reopenHandle(std::string& error) {
  std::vector<MouseInfo> mice;
  MouseInfo info;
  OpenFailure why = OpenFailure::kNone;
  if (!api_->enumerateMice(mice, error) || !findMouseAgain(mice, current_, info, error)) return false;
  if (!openInfo(info, error, why)) return false;
  afterLoss_ = true;
  return true;
}

void EvdevMouseBackend::take(const EvdevEvent& event) {
  if (event.type == kEvSyn && event.code == kSynDropped) {
    // The kernel's queue overflowed: drop what came since the last SYN_REPORT and up to the next.
    dropping_ = true;
    afterLoss_ = true;
    countLoss();
    dx_ = dy_ = 0;
    packetHasData_ = packetSaturated_ = false;
    return;
  }
  if (dropping_) {
    if (event.type == kEvSyn && event.code == kSynReport) {
      dropping_ = false;
      // A press or release may have been among the dropped events: the kernel's key state
      // (EVIOCGKEY) says which buttons are down now (Documentation/input/event-codes.rst,
      // SYN_DROPPED: re-read the state after the next SYN_REPORT). A change goes out at once.
      uint32_t down = buttons_;
      if (handle_->buttonsDown(down) && down != buttons_) {
        buttons_ = down;
        packetHasData_ = true;
        emitPacket(event.timeS);
      }
    }
    return;
  }
  if (event.type == kEvRel && (event.code == kRelX || event.code == kRelY)) {
    (event.code == kRelX ? dx_ : dy_) += event.value;
    packetSaturated_ = packetSaturated_ || limits_.atLimit(event.code == kRelX, event.value);
    packetHasData_ = true;
  } else if (event.type == kEvKey && event.code >= kBtnLeft && event.code <= kBtnTask) {
    const uint32_t bit = 1u << (event.code - kBtnLeft);
    buttons_ = event.value ? buttons_ | bit : buttons_ & ~bit;
    packetHasData_ = true;
  } else if (event.type == kEvSyn && event.code == kSynReport) {
    emitPacket(event.timeS);
  }
}

void EvdevMouseBackend::emitPacket(double kernelTimeS) {
  if (packetHasData_) {
    MouseReport report;
    report.deviceTimeS = (kernelTimestamps_ ? kernelTimeS : monotonicNowS()) - originS();
    report.dxCounts = dx_;
    report.dyCounts = dy_;
    report.buttons = buttons_;
    if (packetSaturated_) report.flags |= kSaturated;
    if (afterLoss_) report.flags |= kAfterLoss;
    afterLoss_ = false;
    emit(report);
  }
  dx_ = dy_ = 0;
  packetHasData_ = packetSaturated_ = false;
}

int EvdevMouseBackend::readSome(int timeoutMs) {
  EvdevEvent events[64];
  int errorCode = 0;
  const int count = handle_->read(events, 64, timeoutMs, &errorCode);
  if (count < 0) {
    setError(current_.path + ": read failed: " + std::strerror(errorCode) +
             (errorCode == ENODEV ? " (unplugged)" : ""));
    return -1;
  }
  for (int i = 0; i < count; ++i) take(events[i]);
  return count > 0 ? 1 : 0;
}

}  // namespace kf
