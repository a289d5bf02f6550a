#include "mouse/HidapiMouseBackend.hpp"

#include "mouse/MouseSelect.hpp"

namespace kf {

std::unique_ptr<HidapiMouseBackend> HidapiMouseBackend::open(std::shared_ptr<HidApi> api, const std::string& which,
                                                             std::string& error, OpenFailure* why,
                                                             const ThreadRequest& thread) {
  if (why) *why = OpenFailure::kOther;
  std::vector<MouseInfo> mice;
  if (!api->enumerateMice(mice, error)) return nullptr;
  std::unique_ptr<HidapiMouseBackend> backend(new HidapiMouseBackend(std::move(api)));
  if (!backend->openSelected(mice, which, error, why, thread)) return nullptr;
  return backend;
}

bool HidapiMouseBackend::openInfo(const MouseInfo& info, std::string& error, OpenFailure& why) {
  std::unique_ptr<HidHandle> handle = api_->openPath(info.path, error, why);
  if (!handle) return false;
  std::vector<uint8_t> bytes;
  HidReportDescriptor descriptor;
  HidMouseDecoder decoder;
  if (!handle->reportDescriptor(bytes, error) ||
      !parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error) || !decoder.build(descriptor, error)) {
    error = info.path + ": " + error;
    why = OpenFailure::kOther;
    return false;
  }
  handle_ = std::move(handle);
  decoder_ = std::move(decoder);
  buttons_ = 0;  // unknown until a report carries them
  current_ = info;
  publishInfo(current_);
  return true;
}

bool HidapiMouseBackend::reopenHandle(std::string& error) {
  std::vector<MouseInfo> mice;
  MouseInfo info;
  OpenFailure why = OpenFailure::kNone;
  if (!api_->enumerateMice(mice, error) || !findMouseAgain(mice, current_, info, error)) return false;
  if (!openInfo(info, error, why)) return false;
  afterLoss_ = true;  // whatever moved while it was away is lost
  return true;
}

void HidapiMouseBackend::take(const uint8_t* bytes, int size, double arrivalS) {
  HidMouseDelta delta;
  if (!decoder_.decode(bytes, static_cast<size_t>(size), delta)) {
    countMalformed();  // too short for its fields, or another report (keyboard part, vendor)
    return;
  }
  MouseReport report;
  report.deviceTimeS = arrivalS;
  report.dxCounts = delta.dxCounts;
  report.dyCounts = delta.dyCounts;
  // A report without buttons (X/Y of a mouse that sends its buttons apart) leaves them as they were.
  if (delta.hasButtons) buttons_ = delta.buttons;
  report.buttons = buttons_;
  // The decoder knows each axis' logical limits (and clamps to them, as the kernel does).
  if (delta.saturated) report.flags |= kSaturated;
  if (afterLoss_) report.flags |= kAfterLoss;
  afterLoss_ = false;
  emit(report);
}

int HidapiMouseBackend::readSome(int timeoutMs) {
  uint8_t buffer[256];
  int size = handle_->readTimeout(buffer, sizeof(buffer), timeoutMs);
  int drained = 0;
  while (size > 0) {
    take(buffer, size, monotonicNowS() - originS());
    ++drained;
    size = handle_->readTimeout(buffer, sizeof(buffer), 0);  // what else is queued, at once
  }
  if (size < 0) {
    setError(current_.path + ": read failed (unplugged?): " + handle_->lastError());
    return -1;
  }
  if (drained >= kKernelQueueReports) {
    // The kernel's queue was full: the reports that came then were dropped.
    countLoss();
    afterLoss_ = true;
  }
  return drained > 0 ? 1 : 0;
}

}  // namespace kf
