// FileDescriptors on POSIX systems (Linux, macOS).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/files/FileDescriptors.hpp"

namespace kf {

int openFileNoWait(const std::string& path, bool forWriting) {
  const int flags = forWriting ? O_WRONLY | O_CREAT : O_RDONLY;
  return ::open(path.c_str(), flags | O_NONBLOCK | O_CLOEXEC, 0644);
}

bool identifyFile(int fd, FileIdentity& out) {
  struct stat info {};
  if (::fstat(fd, &info) != 0) return false;
  out.device = info.st_dev;
  out.inode = info.st_ino;
  out.directory = S_ISDIR(info.st_mode);
  out.regular = S_ISREG(info.st_mode);
  out.size = info.st_size > 0 ? static_cast<uint64_t>(info.st_size) : 0;
  return true;
}

bool makeBlocking(int fd) { return ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK) == 0; }

bool truncateFile(int fd, uint64_t bytes) { return ::ftruncate(fd, static_cast<off_t>(bytes)) == 0; }

long writeFile(int fd, const void* data, size_t size) { return static_cast<long>(::write(fd, data, size)); }

int closeFileDescriptor(int fd) { return ::close(fd); }

std::FILE* readingStream(int fd) { return ::fdopen(fd, "r"); }

}  // namespace kf
