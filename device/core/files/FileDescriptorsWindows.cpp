// FileDescriptors on Windows: the C runtime's descriptors, in binary mode so that a recording's
// bytes are the same as on Linux (no \n to \r\n). A file's identity is its volume serial number
// and file index (st_ino is always 0 there). Windows has no FIFOs a path opens without waiting,
// and no non-blocking regular files: makeBlocking has nothing to do.
#include <fcntl.h>
#include <io.h>
#include <sys/stat.h>
#include <windows.h>

#include <cerrno>

#include "core/files/FileDescriptors.hpp"

namespace kf {

int openFileNoWait(const std::string& path, bool forWriting) {
  const int flags = (forWriting ? _O_WRONLY | _O_CREAT : _O_RDONLY) | _O_BINARY | _O_NOINHERIT;
  return ::_open(path.c_str(), flags, _S_IREAD | _S_IWRITE);
}

bool identifyFile(int fd, FileIdentity& out) {
  const HANDLE handle = reinterpret_cast<HANDLE>(::_get_osfhandle(fd));
  if (handle == INVALID_HANDLE_VALUE) {
    errno = EBADF;
    return false;
  }
  out = FileIdentity{};
  if (::GetFileType(handle) != FILE_TYPE_DISK) return true;  // a pipe, console or device
  BY_HANDLE_FILE_INFORMATION info{};
  if (!::GetFileInformationByHandle(handle, &info)) {
    errno = EIO;
    return false;
  }
  out.device = info.dwVolumeSerialNumber;
  out.inode = (static_cast<unsigned long long>(info.nFileIndexHigh) << 32) | info.nFileIndexLow;
  out.directory = (info.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY) != 0;
  out.regular = !out.directory;
  out.size = (static_cast<uint64_t>(info.nFileSizeHigh) << 32) | info.nFileSizeLow;
  return true;
}

bool makeBlocking(int) { return true; }

bool truncateFile(int fd, uint64_t bytes) { return ::_chsize_s(fd, static_cast<long long>(bytes)) == 0; }

long writeFile(int fd, const void* data, size_t size) {
  return ::_write(fd, data, static_cast<unsigned>(size < 0x7fffffff ? size : 0x7fffffff));
}

int closeFileDescriptor(int fd) { return ::_close(fd); }

std::FILE* readingStream(int fd) { return ::_fdopen(fd, "rb"); }

}  // namespace kf
