#include "recordings/HidRecorderFile.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/files/TextFileReader.hpp"

namespace kf {

namespace {

bool parseHexBytes(std::istringstream& fields, size_t count, std::vector<uint8_t>& out) {
  out.clear();
  std::string token;
  while (fields >> token) {
    if (token.size() != 2 || !std::isxdigit(static_cast<unsigned char>(token[0])) ||
        !std::isxdigit(static_cast<unsigned char>(token[1])))
      return false;
    if (out.size() >= count) return false;
    out.push_back(static_cast<uint8_t>(std::strtoul(token.c_str(), nullptr, 16)));
  }
  return out.size() == count;
}

std::string firstRecordTag(const std::string& path) {
  TextFileReader reader;
  std::string error, line;
  if (!reader.open(path, error)) return {};
  for (;;) {
    const TextFileReader::Line status = reader.next(line, kMaxHidRecorderLineChars);
    if (status != TextFileReader::Line::kOk && status != TextFileReader::Line::kCut) return {};
    if (line.empty() || line[0] == '#') continue;
    return line.substr(0, 2);
  }
}

}  // namespace

bool isHidRecorderFile(const std::string& path) {
  const std::string tag = firstRecordTag(path);
  return tag == "R:" || tag == "D:";
}

bool readHidRecorderFile(const std::string& path, HidRecording& out, std::string& error) {
  out = HidRecording{};
  TextFileReader reader;
  if (!reader.open(path, error)) return false;
  std::string line;
  int device = 0;
  bool haveDescriptor = false;
  for (;;) {
    const auto record = reader.nextRecord(line, kMaxHidRecorderLineChars, haveDescriptor, error, out.warning);
    if (record == TextFileReader::Record::kFailed) return false;
    if (record == TextFileReader::Record::kEnd) break;
    if (line.empty() || line[0] == '#') continue;
    if (line.size() < 2 || line[1] != ':') {
      error = reader.lineError("not a hid-recorder record");
      return false;
    }
    const char tag = line[0];
    const std::string rest = line.size() > 2 ? line.substr(3) : std::string();
    std::istringstream fields(rest);
    fields.imbue(std::locale::classic());
    if (tag == 'D') {
      if (!(fields >> device)) {
        error = reader.lineError("bad D: record");
        return false;
      }
      continue;
    }
    if (device != 0) continue;  // only the first device
    if (tag == 'R') {
      size_t length = 0;
      if (!(fields >> length) || !parseHexBytes(fields, length, out.descriptor)) {
        error = reader.lineError("R: length does not match its bytes, or bad hex");
        return false;
      }
      haveDescriptor = true;
    } else if (tag == 'N') {
      out.name = rest;
    } else if (tag == 'P') {
      out.physicalPath = rest;
    } else if (tag == 'I') {
      if (!(fields >> std::hex >> out.bus >> out.vendorId >> out.productId)) {
        error = reader.lineError("bad I: record");
        return false;
      }
    } else if (tag == 'E') {
      HidRecordedEvent event;
      size_t length = 0;
      std::string timeToken;
      if (!(fields >> timeToken >> length)) {
        error = reader.lineError("bad E: record");
        return false;
      }
      char* end = nullptr;
      event.timeS = std::strtod(timeToken.c_str(), &end);
      if (end != timeToken.c_str() + timeToken.size() || !std::isfinite(event.timeS) ||
          !parseHexBytes(fields, length, event.bytes)) {
        error = reader.lineError("E: time, length or bytes malformed");
        return false;
      }
      out.events.push_back(std::move(event));
    }
    // Other records (e.g. hid-tools' newer optional ones) are ignored.
  }
  if (!haveDescriptor) {
    error = path + ": no R: report descriptor record";
    return false;
  }
  return true;
}

}  // namespace kf
