// SessionFile: the "kf-session" text format of recorded device sessions (docs/record-format.md)
// — formatting it line by line (Recorder; the file itself is RecordingWriter's) and reading a
// whole file back (for ReplayBackend).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/files/RecordingWriter.hpp"
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

// Why the magnet was driven off: the word an off record carries (docs/record-format.md).
enum class OffCause {
  kStop,      // an orderly stop: the last FrictionOut of the slot went away (free, Cmd-., freeAll)
  kQuit,      // the server quit (/quit): halted in order before its audio stopped
  kClose,     // the device closed
  kWatchdog,  // frames stopped without a stop
  kFailure,   // the device thread failed (a backend threw)
  kSignal,    // the server ended on a signal (the signal handler's record)
  kClient,    // the client that watched the device fell silent (Device::watchClient)
};
const char* offCauseName(OffCause cause);

struct RecordedOff {
  double hostTimeS = 0.0;
  std::string cause;  // offCauseName's word; empty in files written before the cause was recorded
};

struct SessionData {
  DeviceSpec spec;
  std::vector<TimedReport> reports;
  std::vector<RecordedFrame> frames;
  std::vector<RecordedOff> offs;  // when the magnet was driven off, and why
  std::string warning;            // e.g. a last line cut mid-way (dropped); empty if none
};

// The header line of a session recorded with `spec` (its newline included).
std::string sessionHeader(const DeviceSpec& spec);

// Formats one session's records as whole lines and hands them to its RecordingWriter. Not
// thread-safe; the Device serialises access (appendOffFromSignal excepted). A failed write
// stops the recording: the file keeps what was written, and error() says why.
class Recorder {
 public:
  Recorder() = default;
  ~Recorder() { close(); }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Records into `writer` (opened with sessionHeader); a recording in progress is closed first.
  void attach(std::unique_ptr<RecordingWriter> writer);
  // attach() of a direct RecordingWriter::open(path, sessionHeader(spec)); false and `error`
  // when the file is refused.
  bool open(const std::string& path, const DeviceSpec& spec, std::string& error);
  void writeReport(double hostTimeS, const MouseReport& report);
  void writeFrame(double hostTimeS, const ForceFrame& frame, float commandedForceN);
  void writeOff(double hostTimeS, OffCause cause);
  // Hands the lines written since to the writer (the file, or a threaded writer's queue).
  // False once the recording failed.
  bool flush();
  // Ends the recording here and returns its writer with every line handed over, for the caller
  // to finish() outside its lock (the last writes may wait on the disk); then noteFinished().
  std::unique_ptr<RecordingWriter> detach();
  void noteFinished(const RecordingWriter& writer);
  // detach(), finish() and noteFinished() in one.
  void close();
  bool isOpen() const { return writer_ != nullptr && !failureSeen_; }
  // Why the last recording stopped by itself (a write error) or could not close, or empty.
  std::string error() const;
  // True once after a failure: the caller posts error().
  bool takeFailure() {
    const bool failed = newFailure_;
    newFailure_ = false;
    return failed;
  }

  // Async-signal-safe (no allocation, no stdio, no lock): appends an off record at hostTimeS,
  // cause signal, with write(2), for the signal handlers that drive the magnet off on the way out. A blank
  // line first, so the record stands on its own line whatever a write cut short left. The file
  // is sealed first (RecordingWriter::sealFromSignal): lines a threaded writer had not written
  // yet (at most its 10 ms period's) are lost with the process, never written after the record.
  void appendOffFromSignal(double hostTimeS) const;

 private:
  void append(const char* text, int length);

  std::unique_ptr<RecordingWriter> writer_;
  std::atomic<RecordingWriter*> signalWriter_{nullptr};  // writer_, for signal handlers
  std::string buffer_;                                   // lines not yet handed over
  bool failureSeen_ = false;
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
