// SessionFile: the "kf-session" text format of recorded device sessions (docs/record-format.md)
// — writing it line by line (Recorder) and reading a whole file back (for ReplayBackend).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "core/spec/DeviceSpec.hpp"
#include "core/spec/Report.hpp"

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

// Writes one session. Not thread-safe; the Device serialises access (appendOffFromSignal
// excepted). Records are gathered in memory and handed to the OS as whole lines, so the file
// ends at a line boundary after every flush. A failed write stops the recording: the file is
// closed keeping what was written, and error() says why. One Recorder per file: a second one
// opening a file that is being recorded (under any path) is refused.
class Recorder {
 public:
  Recorder() = default;
  ~Recorder() { close(); }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Refuses what is not a regular file (a FIFO would block, a device is no recording), and a
  // file another Recorder is writing; truncates only then.
  bool open(const std::string& path, const DeviceSpec& spec, std::string& error);
  void writeReport(double hostTimeS, const MouseReport& report);
  void writeFrame(double hostTimeS, const ForceFrame& frame, float commandedForceN);
  void writeOff(double hostTimeS);
  // Hands what was written to the OS, so that a reader opening the file now (a replay of a
  // session still being recorded) sees every record up to here. False once a write failed.
  bool flush();
  void close();
  bool isOpen() const { return fd_.load(std::memory_order_acquire) >= 0; }
  // Why the last recording stopped by itself (a write error), or empty.
  const std::string& error() const { return error_; }
  // True once after a write failed: the caller posts error().
  bool takeFailure() {
    const bool failed = newFailure_;
    newFailure_ = false;
    return failed;
  }

  // Async-signal-safe (no allocation, no stdio, no lock): appends an off record at hostTimeS
  // with write(2), for the signal handlers that drive the magnet off on the way out. A blank
  // line first, so the record stands on its own line whatever a concurrent write left.
  void appendOffFromSignal(double hostTimeS) const;

 private:
  void append(const char* text, int length);
  void fail(const char* what, int code);

  std::atomic<int> fd_{-1};
  std::string path_;
  std::string buffer_;
  uint64_t bytesWritten_ = 0;
  unsigned long long fileDevice_ = 0, fileInode_ = 0;  // the registry key of one writer per file
  std::string error_;
  bool newFailure_ = false;
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
