#include "core/files/TextFileReader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

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
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
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
  struct stat info {};
  std::string problem;
  if (::fstat(fd, &info) != 0)
    problem = "cannot read " + path + ": " + std::strerror(errno);
  else if (S_ISDIR(info.st_mode))
    problem = path + " is a directory, not a recording";
  else if (!S_ISREG(info.st_mode))
    problem = path + " is not a regular file (a FIFO, device or socket); refused";
  else if (info.st_size == 0)
    problem = path + " is empty";
  else if (static_cast<uint64_t>(info.st_size) > maxBytes)
    problem = path + " is larger than " + std::to_string(maxBytes) + " bytes; refused";
  if (problem.empty() && ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0)
    problem = "cannot read " + path + ": " + std::strerror(errno);
  if (!problem.empty()) {
    ::close(fd);
    error = problem;
    return false;
  }
  file_ = ::fdopen(fd, "r");
  if (file_ == nullptr) {
    ::close(fd);
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
