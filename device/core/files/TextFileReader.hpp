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

  // A recording's next line, with what every recording reader does about next()'s outcomes.
  // kLine: use `line` (cut() says whether the file ended inside it). kEnd: the file ended; or
  // its last line was cut once keepBeforeCut (the caller has what it needs), and `warning` says
  // what was kept. kFailed: a read error or a line over maxChars, in `error`.
  enum class Record { kLine, kEnd, kFailed };
  Record nextRecord(std::string& line, size_t maxChars, bool keepBeforeCut, std::string& error, std::string& warning);
  bool cut() const { return cut_; }
  // "path:line: what", for the line read last.
  std::string lineError(const std::string& what) const;

 private:
  std::string path_;
  bool cut_ = false;
  std::FILE* file_ = nullptr;
  int lineNumber_ = 0;
};

}  // namespace kf
