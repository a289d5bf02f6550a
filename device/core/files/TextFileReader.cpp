#include "core/files/TextFileReader.hpp"

#include <cerrno>
#include <cstring>

#include "core/files/FileDescriptors.hpp"

namespace kf {

TextFileReader::~TextFileReader() {
  if (file_) std::fclose(file_);
}

bool TextFileReader::open(const std::string& path, std::string& error, uint64_t maxBytes) {
  path_ = path;
  if (path.empty()) {
    error = "no file given (empty path)";
    return false;
  }
  // O_NONBLOCK: opening a FIFO must not wait for a writer; the checks below refuse it anyway.
  const int fd = openFileNoWait(path, false);
  if (fd < 0) {
    const int code = errno;
    if (code == ENOENT || code == ENOTDIR)
      error = "no such file: " + path;
    else if (code == EACCES || code == EPERM)
      error = "cannot read " + path + ": permission denied";
    else
      error = "cannot open " + path + ": " + std::strerror(code);
    return false;
  }
  FileIdentity info;
  std::string problem;
  if (!identifyFile(fd, info))
    problem = "cannot read " + path + ": " + std::strerror(errno);
  else if (info.directory)
    problem = path + " is a directory, not a recording";
  else if (!info.regular)
    problem = path + " is not a regular file (a FIFO, device or socket); refused";
  else if (info.size == 0)
    problem = path + " is empty";
  else if (info.size > maxBytes)
    problem = path + " is larger than " + std::to_string(maxBytes) + " bytes; refused";
  if (problem.empty() && !makeBlocking(fd)) problem = "cannot read " + path + ": " + std::strerror(errno);
  if (!problem.empty()) {
    closeFileDescriptor(fd);
    error = problem;
    return false;
  }
  file_ = readingStream(fd);
  if (file_ == nullptr) {
    closeFileDescriptor(fd);
    error = "cannot read " + path + ": " + std::strerror(errno);
    return false;
  }
  lineNumber_ = 0;
  return true;
}

TextFileReader::Line TextFileReader::next(std::string& line, size_t maxChars) {
  line.clear();
  if (file_ == nullptr) return Line::kEnd;
  int c = 0;
  while ((c = std::getc(file_)) != EOF && c != '\n') {
    if (line.size() >= maxChars) {
      ++lineNumber_;
      return Line::kTooLong;
    }
    line.push_back(static_cast<char>(c));
  }
  if (c == EOF && std::ferror(file_)) return Line::kError;
  if (c == EOF && line.empty()) return Line::kEnd;
  ++lineNumber_;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return c == EOF ? Line::kCut : Line::kOk;
}

TextFileReader::Record TextFileReader::nextRecord(std::string& line, size_t maxChars, bool keepBeforeCut,
                                                  std::string& error, std::string& warning) {
  const Line status = next(line, maxChars);
  cut_ = status == Line::kCut;
  switch (status) {
    case Line::kEnd:
      return Record::kEnd;
    case Line::kError:
      error = lineError("read error");
      return Record::kFailed;
    case Line::kTooLong:
      error = lineError("line longer than " + std::to_string(maxChars) + " characters");
      return Record::kFailed;
    case Line::kCut:
      // Writers end every line with '\n': a last line without it was cut (a crash, a full disk).
      if (!keepBeforeCut) return Record::kLine;
      warning = lineError("the last line was cut; loaded the " + std::to_string(lineNumber_ - 1) + " lines before it");
      return Record::kEnd;
    case Line::kOk:
      break;
  }
  return Record::kLine;
}

std::string TextFileReader::lineError(const std::string& what) const {
  return path_ + ":" + std::to_string(lineNumber_) + ": " + what;
}

}  // namespace kf
