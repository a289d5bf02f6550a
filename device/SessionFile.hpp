// SessionFile: the "kf-session" text format of recorded device sessions (docs/record-format.md)
// — writing it line by line (Recorder) and reading a whole file back (for ReplayBackend).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "DeviceSpec.hpp"
#include "Report.hpp"

namespace kf {

constexpr const char* kSessionFormatName = "kf-session";
constexpr int kSessionFormatVersion = 1;

// A report with the host time (seconds since open) at which the device thread received it.
struct TimedReport {
  double hostTimeS = 0.0;
  MouseReport report;
};

struct RecordedFrame {
  double hostTimeS = 0.0;
  ForceFrame frame;              // as requested by the audio side
  float commandedForceN = 0.0f;  // after ForceSafety
};

struct SessionData {
  DeviceSpec spec;
  std::vector<TimedReport> reports;
  std::vector<RecordedFrame> frames;
  std::vector<double> offTimesS;  // host times the magnet was driven off
  std::string warning;            // e.g. a last line cut mid-way (dropped); empty if none
};

// Writes one session. Not thread-safe; the Device serialises access.
class Recorder {
 public:
  Recorder() = default;
  ~Recorder() { close(); }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  bool open(const std::string& path, const DeviceSpec& spec, std::string& error);
  void writeReport(double hostTimeS, const MouseReport& report);
  void writeFrame(double hostTimeS, const ForceFrame& frame, float commandedForceN);
  void writeOff(double hostTimeS);
  // Hands what was written to the OS, so that a reader opening the file now (a replay of a
  // session still being recorded) sees every record up to here.
  void flush();
  void close();
  bool isOpen() const { return file_ != nullptr; }

 private:
  std::FILE* file_ = nullptr;
};

constexpr size_t kMaxSessionLineChars = 4096;

// True if the file starts with the kf-session header line (false for anything that is not a
// regular file: it is never read).
bool isSessionFile(const std::string& path);
// Reads a whole kf-session file; the header's fields override those of `spec` in out.spec.
// Header values outside their bounds (SettingBounds) and lines longer than
// kMaxSessionLineChars are errors; a last line without its newline (a recording cut short)
// is dropped with out.warning.
bool readSessionFile(const std::string& path, const DeviceSpec& spec, SessionData& out, std::string& error);

}  // namespace kf
