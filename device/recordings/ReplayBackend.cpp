#include "recordings/ReplayBackend.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/files/TextFileReader.hpp"
#include "core/spec/SettingBounds.hpp"
#include "hid/HidMouseDecoder.hpp"
#include "hid/HidReportDescriptor.hpp"
#include "recordings/HidRecorderFile.hpp"

namespace kf {

bool ReplayOptions::applyOverride(std::string_view key, double value, std::string* error) {
  double ReplayOptions::*number = key == "startS" ? &ReplayOptions::startS
                                  : key == "rate" ? &ReplayOptions::rate
                                                  : nullptr;
  bool ReplayOptions::*flag = key == "skipIdle" ? &ReplayOptions::skipIdle
                              : key == "loop"   ? &ReplayOptions::loop
                                                : nullptr;
  std::string message;
  if (number == nullptr && flag == nullptr)
    message = "unknown replay setting '" + std::string(key) + "'";
  else
    message = checkSetting(key, value);
  if (!message.empty()) {
    if (error != nullptr) *error = message;
    return false;
  }
  if (number != nullptr)
    this->*number = value;
  else
    this->*flag = value != 0.0;
  return true;
}

ReplayBackend::ReplayBackend(std::vector<TimedReport> reports, const ReplayOptions& options, double updateRateHz)
    : reports_(std::move(reports)), options_(options) {
  if (!(options_.rate > 0.0) || !std::isfinite(options_.rate)) options_.rate = 1.0;
  const double intervalS = 1.0 / (updateRateHz > 0.0 ? updateRateHz : 125.0);
  double startS = options_.startS;
  if (options_.skipIdle) {
    for (const TimedReport& r : reports_) {
      if (r.hostTimeS >= startS && (r.report.dxCounts != 0 || r.report.dyCounts != 0)) {
        startS = std::max(startS, r.hostTimeS - intervalS);
        break;
      }
    }
  }
  // Without options the file plays on its own clock, as recorded (start 0, rate 1).
  const bool retimed = startS > 0.0 || options_.rate != 1.0 || options_.loop;
  startFileS_ = retimed ? startS : 0.0;
  while (first_ < reports_.size() && reports_[first_].hostTimeS < startFileS_) ++first_;
  next_ = first_;
  if (first_ < reports_.size()) periodFileS_ = reports_.back().hostTimeS - startFileS_ + intervalS;
}

int ReplayBackend::pollReports(double untilTimeS, MouseReport* out, int capacity) {
  int written = 0;
  while (written < capacity) {
    if (next_ >= reports_.size()) {
      if (!options_.loop || first_ >= reports_.size() || !(periodFileS_ > 0.0)) break;
      next_ = first_;  // the next pass: the puck carries on from where the last one left it
      passOffsetS_ += periodFileS_ / options_.rate;
    }
    const TimedReport& r = reports_[next_];
    if (replayTimeS(r.hostTimeS) > untilTimeS) break;
    MouseReport report = r.report;
    report.deviceTimeS = replayTimeS(r.report.deviceTimeS);
    out[written++] = report;
    ++next_;
  }
  return written;
}

bool loadReplayReports(const std::string& path, DeviceSpec& spec, std::vector<TimedReport>& out, std::string& error,
                       size_t* skippedEvents, std::string* warning) {
  out.clear();
  if (skippedEvents) *skippedEvents = 0;
  if (warning) warning->clear();
  {
    TextFileReader probe;  // the file's own problem first, not "neither format"
    if (!probe.open(path, error)) return false;
  }
  if (isSessionFile(path)) {
    SessionData session;
    if (!readSessionFile(path, spec, session, error)) return false;
    if (warning) *warning = session.warning;
    spec = session.spec;
    out = std::move(session.reports);
    return true;
  }
  if (!isHidRecorderFile(path)) {
    error = path + ": neither a kf-session nor a hid-recorder file";
    return false;
  }
  HidRecording recording;
  if (!readHidRecorderFile(path, recording, error)) return false;
  if (warning) *warning = recording.warning;
  HidReportDescriptor descriptor;
  if (!parseHidReportDescriptor(recording.descriptor.data(), recording.descriptor.size(), descriptor, error))
    return false;
  HidMouseDecoder decoder;
  if (!decoder.build(descriptor, error)) return false;
  size_t saturated = 0;
  uint32_t buttons = 0;  // as the last report that carried them left them
  for (const HidRecordedEvent& event : recording.events) {
    HidMouseDelta delta;
    if (!decoder.decode(event.bytes.data(), event.bytes.size(), delta)) {
      if (skippedEvents) ++*skippedEvents;
      continue;
    }
    TimedReport timed;
    timed.hostTimeS = event.timeS;
    timed.report.deviceTimeS = event.timeS;
    timed.report.dxCounts = delta.dxCounts;
    timed.report.dyCounts = delta.dyCounts;
    if (delta.hasButtons) buttons = delta.buttons;
    timed.report.buttons = buttons;
    if (delta.saturated) {
      timed.report.flags |= kSaturated;
      ++saturated;
    }
    out.push_back(timed);
  }
  if (saturated > 0 && warning) {
    if (!warning->empty()) *warning += "; ";
    *warning += std::to_string(saturated) + " of " + std::to_string(out.size()) +
                " reports at their field's limit (flagged saturated: the mouse moved at least that far, the "
                "excess is lost; a higher report rate or a lower resolution keeps it)";
  }
  return true;
}

}  // namespace kf
