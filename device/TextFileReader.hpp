// TextFileReader: reads a recording line by line with every size bounded. It refuses, before
// reading a byte, what is not a regular file (FIFOs would block, /dev/zero never ends),
// directories, empty and oversized files, each with its own message; lines longer than the
// caller's cap stop the reading, and a last line without its newline is reported as cut.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace kf {

constexpr uint64_t kMaxRecordingBytes = uint64_t(1) << 30;  // 1 GiB: hours of 1 kHz frames

class TextFileReader {
 public:
  enum class Line { kOk, kEnd, kTooLong, kCut, kError };

  TextFileReader() = default;
  ~TextFileReader();
  TextFileReader(const TextFileReader&) = delete;
  TextFileReader& operator=(const TextFileReader&) = delete;

  // False with a message: missing, unreadable, a directory, not a regular file, empty, or
  // larger than maxBytes.
  bool open(const std::string& path, std::string& error, uint64_t maxBytes = kMaxRecordingBytes);
  // The next line without its '\n' (and a trailing '\r'). kCut: the file ended inside a line
  // (`line` holds what there was); kTooLong: more than maxChars before the newline; kError:
  // the system failed to read.
  Line next(std::string& line, size_t maxChars);
  int lineNumber() const { return lineNumber_; }

 private:
  std::FILE* file_ = nullptr;
  int lineNumber_ = 0;
};

}  // namespace kf
