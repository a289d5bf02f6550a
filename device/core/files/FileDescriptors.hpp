// The file calls the recordings (RecordingWriter, Recorder's off record from a signal handler)
// and the readers (TextFileReader) make, on descriptors of the C runtime, with one file per
// system: FileDescriptorsPosix.cpp (open, fstat, fcntl, ftruncate, write) and
// FileDescriptorsWindows.cpp (the CRT's _open in binary mode, the file index for identity).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace kf {

struct FileIdentity {
  unsigned long long device = 0, inode = 0;  // two paths to one file give the same pair
  bool directory = false;
  bool regular = false;  // not a FIFO, device or socket
  uint64_t size = 0;
};

// Opens `path` for reading, or for writing (created with mode 0644, not truncated), without
// waiting for a FIFO's other end and not inherited by child processes; -1 with errno set.
int openFileNoWait(const std::string& path, bool forWriting);
// What the descriptor refers to; false with errno set.
bool identifyFile(int fd, FileIdentity& out);
// Blocking I/O again after openFileNoWait; false with errno set.
bool makeBlocking(int fd);
// Cuts the file to `bytes`; false with errno set.
bool truncateFile(int fd, uint64_t bytes);
// Bytes written, or -1 with errno set. Async-signal-safe where the system has signals.
long writeFile(int fd, const void* data, size_t size);
// 0, or -1 with errno set.
int closeFileDescriptor(int fd);
// A stdio stream reading the descriptor (which it then owns), bytes as they are in the file;
// null with errno set.
std::FILE* readingStream(int fd);

}  // namespace kf
