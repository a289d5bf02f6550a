#include "ReplayBackend.hpp"

#include "HidMouseDecoder.hpp"
#include "HidRecorderFile.hpp"
#include "HidReportDescriptor.hpp"
#include "TextFileReader.hpp"

namespace kf {

int ReplayBackend::pollReports(double untilTimeS, MouseReport* out, int capacity) {
  int written = 0;
  while (written < capacity && next_ < reports_.size() && reports_[next_].hostTimeS <= untilTimeS)
    out[written++] = reports_[next_++].report;
  return written;
}

void CountingForceSink::commandForce(double timeS, float forceN) {
  lastForceN_.store(forceN, std::memory_order_relaxed);
  lastTimeS_.store(timeS, std::memory_order_relaxed);
  commands_.fetch_add(1, std::memory_order_relaxed);
}

void CountingForceSink::driveOff() { driveOffs_.fetch_add(1, std::memory_order_relaxed); }

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
    timed.report.buttons = delta.buttons;
    out.push_back(timed);
  }
  return true;
}

}  // namespace kf
