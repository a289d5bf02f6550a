#include "SessionFile.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "SettingBounds.hpp"
#include "TextFileReader.hpp"

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

std::string lineError(const std::string& path, int lineNumber, const std::string& what) {
  return path + ":" + std::to_string(lineNumber) + ": " + what;
}

}  // namespace

bool Recorder::open(const std::string& path, const DeviceSpec& spec, std::string& error) {
  close();
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) {
    error = "cannot write " + path + ": " + std::strerror(errno);
    return false;
  }
  std::fprintf(file_, "%s %d", kSessionFormatName, kSessionFormatVersion);
  for (const SpecField& field : kSpecFields) std::fprintf(file_, " %s=%.17g", field.name, field.get(spec));
  std::fprintf(file_, "\n");
  return true;
}

void Recorder::writeReport(double hostTimeS, const MouseReport& r) {
  if (!file_) return;
  // %.17g: doubles read back bit for bit.
  std::fprintf(file_, "R %.17g %.17g %d %d %u %u\n", hostTimeS, r.deviceTimeS, r.dxCounts, r.dyCounts, r.buttons,
               r.flags);
}

void Recorder::writeFrame(double hostTimeS, const ForceFrame& frame, float commandedForceN) {
  if (!file_) return;
  std::fprintf(file_, "F %.17g %.17g %.9g %.9g\n", hostTimeS, frame.timeS, static_cast<double>(frame.forceN),
               static_cast<double>(commandedForceN));
}

void Recorder::writeOff(double hostTimeS) {
  if (!file_) return;
  std::fprintf(file_, "O %.17g\n", hostTimeS);
}

void Recorder::flush() {
  if (file_) std::fflush(file_);
}

void Recorder::close() {
  if (file_) std::fclose(file_);
  file_ = nullptr;
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
    const TextFileReader::Line status = reader.next(line, kMaxSessionLineChars);
    const int lineNumber = reader.lineNumber();
    if (status == TextFileReader::Line::kEnd) break;
    if (status == TextFileReader::Line::kError) {
      error = lineError(path, lineNumber, "read error");
      return false;
    }
    if (status == TextFileReader::Line::kTooLong) {
      error = lineError(path, lineNumber, "line longer than " + std::to_string(kMaxSessionLineChars) + " characters");
      return false;
    }
    if (status == TextFileReader::Line::kCut && haveHeader) {
      // Recorder ends every line with '\n': a last line without it was cut (a crash, a full
      // disk). Everything before it is kept.
      out.warning = lineError(
          path, lineNumber, "the last line was cut; loaded the " + std::to_string(lineNumber - 1) + " lines before it");
      break;
    }
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    fields.imbue(std::locale::classic());
    std::string tag;
    fields >> tag;
    if (!haveHeader) {
      int version = 0;
      if (tag != kSessionFormatName || !(fields >> version)) {
        error = lineError(path, lineNumber, "not a kf-session file");
        return false;
      }
      if (version != kSessionFormatVersion) {
        error = lineError(path, lineNumber, "unsupported kf-session version " + std::to_string(version));
        return false;
      }
      std::string pair;
      while (fields >> pair) {
        const size_t equals = pair.find('=');
        if (equals == std::string::npos) {
          error = lineError(path, lineNumber, "header field without '=': " + pair);
          return false;
        }
        const std::string key = pair.substr(0, equals);
        double value = 0.0;
        if (!parseDouble(pair.substr(equals + 1), value)) {
          error = lineError(path, lineNumber, "bad value in header field " + pair);
          return false;
        }
        // Unknown keys are skipped so newer files still load; known ones must be in bounds.
        if (findSettingBounds(key) == nullptr) continue;
        std::string why;
        if (!out.spec.applyOverride(key, value, &why)) {
          if (why.rfind("unknown", 0) == 0) continue;  // a bounded name that is not a spec field
          error = lineError(path, lineNumber, "header: " + why);
          return false;
        }
      }
      std::string why;
      if (!out.spec.isValid(&why)) {
        error = lineError(path, lineNumber, "header: " + why);
        return false;
      }
      haveHeader = true;
      if (status == TextFileReader::Line::kCut) break;  // a header alone, cut after its last field
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
      double timeS = 0.0;
      ok = tokens.size() == 1 && parseDouble(tokens[0], timeS) && std::isfinite(timeS);
      if (ok) out.offTimesS.push_back(timeS);
    } else {
      error = lineError(path, lineNumber, "unknown record '" + tag.substr(0, 32) + "'");
      return false;
    }
    if (!ok) {
      error = lineError(path, lineNumber, "malformed '" + tag + "' record");
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
