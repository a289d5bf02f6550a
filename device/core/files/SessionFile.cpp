#include "core/files/SessionFile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <utility>

#include "core/files/FileDescriptors.hpp"
#include "core/files/TextFileReader.hpp"
#include "core/spec/SettingBounds.hpp"

namespace kf {

namespace {

// The DeviceSpec fields, in header order.
struct SpecField {
  const char* name;
  double (*get)(const DeviceSpec&);
};
const SpecField kSpecFields[] = {
    {"countMm", [](const DeviceSpec& s) { return s.countMm; }},
    {"updateRateHz", [](const DeviceSpec& s) { return s.updateRateHz; }},
    {"maxCountsPerReport", [](const DeviceSpec& s) { return double(s.maxCountsPerReport); }},
    {"minForceN", [](const DeviceSpec& s) { return s.minForceN; }},
    {"maxForceN", [](const DeviceSpec& s) { return s.maxForceN; }},
    {"audioLatencyS", [](const DeviceSpec& s) { return s.audioLatencyS; }},
    {"tactileLatencyS", [](const DeviceSpec& s) { return s.tactileLatencyS; }},
    {"forceFramePeriodS", [](const DeviceSpec& s) { return s.forceFramePeriodS; }},
    {"maxForceSlewNPerS", [](const DeviceSpec& s) { return s.maxForceSlewNPerS; }},
    {"watchdogS", [](const DeviceSpec& s) { return s.watchdogS; }},
    {"magnetLagS", [](const DeviceSpec& s) { return s.magnetLagS; }},
    {"countMmY", [](const DeviceSpec& s) { return s.countMmY; }},  // the reports' counts are the mouse's
    {"swapXY", [](const DeviceSpec& s) { return s.swapXY; }},
    {"signX", [](const DeviceSpec& s) { return s.signX; }},
    {"signY", [](const DeviceSpec& s) { return s.signY; }},
};

// strtod, unlike istream, reads back the "nan" and "inf" a requested force may hold.
bool parseDouble(const std::string& token, double& value) {
  if (token.empty()) return false;
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end);
  return end == token.c_str() + token.size();
}

template <typename Integer>
bool parseInteger(const std::string& token, Integer& value) {
  if (token.empty()) return false;
  char* end = nullptr;
  const long long parsed = std::strtoll(token.c_str(), &end, 10);
  if (end != token.c_str() + token.size()) return false;
  value = static_cast<Integer>(parsed);
  return static_cast<long long>(value) == parsed;
}

bool parseFloat(const std::string& token, float& value) {
  double parsed = 0.0;
  if (!parseDouble(token, parsed)) return false;
  value = static_cast<float>(parsed);
  return true;
}

constexpr size_t kRecorderBufferBytes = 64 * 1024;  // handed over when a pump fills it

}  // namespace

std::string sessionHeader(const DeviceSpec& spec) {
  std::string header = std::string(kSessionFormatName) + " " + std::to_string(kSessionFormatVersion);
  char field[96];
  for (const SpecField& entry : kSpecFields) {
    const int length = std::snprintf(field, sizeof field, " %s=%.17g", entry.name, entry.get(spec));
    header.append(field, static_cast<size_t>(std::min<int>(length, sizeof field - 1)));
  }
  return header + '\n';
}

void Recorder::attach(std::unique_ptr<RecordingWriter> writer) {
  close();
  error_.clear();
  newFailure_ = false;
  failureSeen_ = false;
  buffer_.clear();
  buffer_.reserve(kRecorderBufferBytes + 512);
  writer_ = std::move(writer);
  signalWriter_.store(writer_.get(), std::memory_order_release);
}

bool Recorder::open(const std::string& path, const DeviceSpec& spec, std::string& error) {
  close();
  std::unique_ptr<RecordingWriter> writer = RecordingWriter::open(path, sessionHeader(spec), false, 0, error);
  if (!writer) return false;
  attach(std::move(writer));
  return true;
}

void Recorder::append(const char* text, int length) {
  if (!isOpen() || length <= 0) return;
  buffer_.append(text, static_cast<size_t>(length));
  if (buffer_.size() >= kRecorderBufferBytes) flush();  // whole lines only: `text` is one
}

void Recorder::writeReport(double hostTimeS, const MouseReport& r) {
  if (!isOpen()) return;
  // %.17g: doubles read back bit for bit.
  char line[160];
  const int length = std::snprintf(line, sizeof line, "R %.17g %.17g %d %d %u %u\n", hostTimeS, r.deviceTimeS,
                                   r.dxCounts, r.dyCounts, r.buttons, r.flags);
  append(line, std::min<int>(length, sizeof line - 1));
}

void Recorder::writeFrame(double hostTimeS, const ForceFrame& frame, float commandedForceN) {
  if (!isOpen()) return;
  char line[160];
  const int length = std::snprintf(line, sizeof line, "F %.17g %.17g %.9g %.9g\n", hostTimeS, frame.timeS,
                                   static_cast<double>(frame.forceN), static_cast<double>(commandedForceN));
  append(line, std::min<int>(length, sizeof line - 1));
}

const char* offCauseName(OffCause cause) {
  switch (cause) {
    case OffCause::kStop:
      return "stop";
    case OffCause::kQuit:
      return "quit";
    case OffCause::kClose:
      return "close";
    case OffCause::kWatchdog:
      return "watchdog";
    case OffCause::kFailure:
      return "failure";
    case OffCause::kSignal:
      return "signal";
    case OffCause::kClient:
      return "client";
  }
  return "unknown";
}

void Recorder::writeOff(double hostTimeS, OffCause cause) {
  if (!isOpen()) return;
  char line[64];
  const int length = std::snprintf(line, sizeof line, "O %.17g %s\n", hostTimeS, offCauseName(cause));
  append(line, std::min<int>(length, sizeof line - 1));
}

bool Recorder::flush() {
  if (!writer_) return error_.empty();
  if (failureSeen_) return false;
  if (writer_->hand(buffer_)) return true;
  failureSeen_ = true;
  newFailure_ = true;
  return false;
}

std::unique_ptr<RecordingWriter> Recorder::detach() {
  if (!writer_) return nullptr;
  flush();
  signalWriter_.store(nullptr, std::memory_order_release);
  buffer_.clear();
  return std::move(writer_);
}

void Recorder::noteFinished(const RecordingWriter& writer) {
  std::string why = writer.error();
  if (why.empty()) return;
  // A failure the recording thread saw was flagged then; a close error is new.
  if (!failureSeen_) newFailure_ = true;
  error_ = std::move(why);
}

void Recorder::close() {
  std::unique_ptr<RecordingWriter> writer = detach();
  if (!writer) return;
  writer->finish();
  noteFinished(*writer);
}

std::string Recorder::error() const {
  if (writer_) return failureSeen_ ? writer_->error() : std::string();
  return error_;
}

void Recorder::appendOffFromSignal(double hostTimeS) const {
  RecordingWriter* writer = signalWriter_.load(std::memory_order_acquire);
  const int fd = writer ? writer->sealFromSignal() : -1;
  if (fd < 0) return;
  // "\nO <seconds>.<nanoseconds> signal\n" by hand: snprintf is not async-signal-safe.
  char text[56];
  int n = 0;
  text[n++] = '\n';
  text[n++] = 'O';
  text[n++] = ' ';
  if (!(hostTimeS >= 0.0) || hostTimeS > 4e9) hostTimeS = 0.0;
  const auto whole = static_cast<uint64_t>(hostTimeS);
  const auto nanos = static_cast<uint64_t>((hostTimeS - static_cast<double>(whole)) * 1e9);
  char digits[24];
  int d = 0;
  uint64_t value = whole;
  do {
    digits[d++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value > 0);
  while (d > 0) text[n++] = digits[--d];
  text[n++] = '.';
  for (uint64_t scale = 100000000; scale > 0; scale /= 10) text[n++] = static_cast<char>('0' + (nanos / scale) % 10);
  text[n++] = ' ';
  for (const char* c = offCauseName(OffCause::kSignal); *c != '\0'; ++c) text[n++] = *c;
  text[n++] = '\n';
  (void)writeFile(fd, text, static_cast<size_t>(n));
}

bool isSessionFile(const std::string& path) {
  TextFileReader reader;
  std::string error, line;
  if (!reader.open(path, error)) return false;
  const TextFileReader::Line status = reader.next(line, kMaxSessionLineChars);
  if (status != TextFileReader::Line::kOk && status != TextFileReader::Line::kCut) return false;
  return line.compare(0, std::strlen(kSessionFormatName), kSessionFormatName) == 0 &&
         (line.size() == std::strlen(kSessionFormatName) || line[std::strlen(kSessionFormatName)] == ' ');
}

bool readSessionFile(const std::string& path, const DeviceSpec& spec, SessionData& out, std::string& error) {
  out = SessionData{};
  out.spec = spec;
  TextFileReader reader;
  if (!reader.open(path, error)) return false;
  std::string line;
  bool haveHeader = false;
  for (;;) {
    const auto record = reader.nextRecord(line, kMaxSessionLineChars, haveHeader, error, out.warning);
    if (record == TextFileReader::Record::kFailed) return false;
    if (record == TextFileReader::Record::kEnd) break;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    fields.imbue(std::locale::classic());
    std::string tag;
    fields >> tag;
    if (!haveHeader) {
      int version = 0;
      if (tag != kSessionFormatName || !(fields >> version)) {
        error = reader.lineError("not a kf-session file");
        return false;
      }
      if (version != kSessionFormatVersion) {
        error = reader.lineError("unsupported kf-session version " + std::to_string(version));
        return false;
      }
      std::string pair;
      while (fields >> pair) {
        const size_t equals = pair.find('=');
        if (equals == std::string::npos) {
          error = reader.lineError("header field without '=': " + pair);
          return false;
        }
        const std::string key = pair.substr(0, equals);
        double value = 0.0;
        if (!parseDouble(pair.substr(equals + 1), value)) {
          error = reader.lineError("bad value in header field " + pair);
          return false;
        }
        // Unknown keys are skipped so newer files still load; known ones must be in bounds.
        if (findSettingBounds(key) == nullptr) continue;
        std::string why;
        if (!out.spec.applyOverride(key, value, &why)) {
          if (why.rfind("unknown", 0) == 0) continue;  // a bounded name that is not a spec field
          error = reader.lineError("header: " + why);
          return false;
        }
      }
      std::string why;
      if (!out.spec.isValid(&why)) {
        error = reader.lineError("header: " + why);
        return false;
      }
      haveHeader = true;
      if (reader.cut()) break;  // a header alone, cut after its last field
      continue;
    }
    std::vector<std::string> tokens;
    for (std::string token; tokens.size() < 8 && fields >> token;) tokens.push_back(token);
    bool ok = false;
    if (tag == "R") {
      TimedReport timed;
      MouseReport& r = timed.report;
      ok = tokens.size() == 6 && parseDouble(tokens[0], timed.hostTimeS) && parseDouble(tokens[1], r.deviceTimeS) &&
           parseInteger(tokens[2], r.dxCounts) && parseInteger(tokens[3], r.dyCounts) &&
           parseInteger(tokens[4], r.buttons) && parseInteger(tokens[5], r.flags) && std::isfinite(timed.hostTimeS) &&
           std::isfinite(r.deviceTimeS);  // replay waits for hostTimeS
      if (ok) out.reports.push_back(timed);
    } else if (tag == "F") {
      RecordedFrame recorded;
      ok = tokens.size() == 4 && parseDouble(tokens[0], recorded.hostTimeS) &&
           parseDouble(tokens[1], recorded.frame.timeS) && parseFloat(tokens[2], recorded.frame.forceN) &&
           parseFloat(tokens[3], recorded.commandedForceN);
      if (ok) out.frames.push_back(recorded);
    } else if (tag == "O") {
      // The cause is optional: files written before it was recorded have none.
      RecordedOff off;
      ok = (tokens.size() == 1 || tokens.size() == 2) && parseDouble(tokens[0], off.hostTimeS) &&
           std::isfinite(off.hostTimeS);
      if (ok && tokens.size() == 2) off.cause = tokens[1].substr(0, 32);
      if (ok) out.offs.push_back(off);
    } else {
      error = reader.lineError("unknown record '" + tag.substr(0, 32) + "'");
      return false;
    }
    if (!ok) {
      error = reader.lineError("malformed '" + tag + "' record");
      return false;
    }
  }
  if (!haveHeader) {
    error = path + ": no kf-session header (only comments or blank lines)";
    return false;
  }
  return true;
}

}  // namespace kf
