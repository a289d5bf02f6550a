#include "core/files/RecordingWriter.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>
#include <vector>

#include "core/files/FileDescriptors.hpp"
#include "core/threads/ThreadScheduling.hpp"

namespace kf {

namespace {

// Files being recorded, by (device, inode): two paths to one file are one file. Never destroyed:
// the plugin's exit hook, itself a static destructor, closes recordings after this file's own
// statics may be gone.
struct RecordingFiles {
  std::mutex mutex;
  std::vector<std::pair<unsigned long long, unsigned long long>> keys;
};
RecordingFiles& recordingFiles() {
  static RecordingFiles* files = new RecordingFiles;
  return *files;
}

bool writeAll(int fd, const char* data, size_t size, int& code) {
  while (size > 0) {
    const long written = writeFile(fd, data, size);
    if (written < 0) {
      if (errno == EINTR) continue;
      code = errno;
      return false;
    }
    if (written == 0) {
      code = EIO;
      return false;
    }
    data += written;
    size -= static_cast<size_t>(written);
  }
  return true;
}

// Opens `path` as a recording no other one writes, truncated; -1 and `error` if refused.
int openRecordingFile(const std::string& path, unsigned long long& fileDevice, unsigned long long& fileInode,
                      std::string& error) {
  if (path.empty()) {
    error = "no file given (empty path)";
    return -1;
  }
  // No O_TRUNC yet: a file another recording writes must not be cut. O_NONBLOCK: a FIFO
  // without a reader must not block the command thread.
  const int fd = openFileNoWait(path, true);
  if (fd < 0) {
    const int code = errno;
    if (code == ENXIO)  // a FIFO without a reader, a device without its driver
      error = "cannot record to " + path + ": not a regular file (a FIFO, device or socket)";
    else
      error = "cannot write " + path + ": " + std::strerror(code);
    return -1;
  }
  FileIdentity info;
  std::string problem;
  if (!identifyFile(fd, info))
    problem = "cannot write " + path + ": " + std::strerror(errno);
  else if (info.directory)
    problem = path + " is a directory";
  else if (!info.regular)
    problem = "cannot record to " + path + ": not a regular file (a FIFO, device or socket)";
  if (problem.empty()) {
    RecordingFiles& files = recordingFiles();
    std::lock_guard<std::mutex> lock(files.mutex);
    const std::pair<unsigned long long, unsigned long long> key{info.device, info.inode};
    if (std::find(files.keys.begin(), files.keys.end(), key) != files.keys.end()) {
      problem = "cannot record to " + path + ": another device is recording to this file";
    } else if (!truncateFile(fd, 0) || !makeBlocking(fd)) {
      problem = "cannot write " + path + ": " + std::strerror(errno);
    } else {
      files.keys.push_back(key);
      fileDevice = key.first;
      fileInode = key.second;
    }
  }
  if (!problem.empty()) {
    closeFileDescriptor(fd);
    error = problem;
    return -1;
  }
  return fd;
}

}  // namespace

RecordingWriter::RecordingWriter(int fd, std::string path, unsigned long long fileDevice, unsigned long long fileInode)
    : fd_(fd), path_(std::move(path)), fileDevice_(fileDevice), fileInode_(fileInode) {}

std::unique_ptr<RecordingWriter> RecordingWriter::open(const std::string& path, const std::string& header,
                                                       bool threaded, int slot, std::string& error) {
  unsigned long long fileDevice = 0, fileInode = 0;
  const int fd = openRecordingFile(path, fileDevice, fileInode, error);
  if (fd < 0) return nullptr;
  std::unique_ptr<RecordingWriter> writer(new RecordingWriter(fd, path, fileDevice, fileInode));
  if (!writer->writeOut(header)) {
    error = writer->error();
    return nullptr;
  }
  if (threaded) {
    writer->queue_.reserve(kQueueBytes);
    writer->writing_.reserve(kQueueBytes);
    writer->writer_ = std::thread([w = writer.get(), slot] { w->writerLoop(slot); });
  }
  return writer;
}

bool RecordingWriter::hand(std::string& lines) {
  if (failed() || overflowed_.load(std::memory_order_relaxed)) {
    lines.clear();
    return false;
  }
  if (lines.empty()) return true;
  if (!writer_.joinable()) {  // direct
    const bool written = writeOut(lines);
    lines.clear();
    return written;
  }
  bool accepted = false;
  {
    std::lock_guard<PiMutex> lock(queueMutex_);
    // Within the reserved capacity, so the copy never allocates.
    accepted = queue_.size() + lines.size() <= kQueueBytes;
    if (accepted) queue_.append(lines);
  }
  lines.clear();
  if (!accepted) overflowed_.store(true, std::memory_order_release);
  return accepted;
}

void RecordingWriter::writerLoop(int slot) {
  // Normal priority on purpose: the writes may wait on the disk, and nothing waits on them.
  scheduleThisThread("rec", ThreadRequest{slot, kNormalPriority});
  for (;;) {
    bool stopping = false;
    {
      std::unique_lock<std::mutex> lock(wakeMutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(kWritePeriodMs), [this] { return stopping_; });
      stopping = stopping_;
    }
    // Read before the queue is taken: every line handed before the overflow is in it.
    const bool overflowed = overflowed_.load(std::memory_order_acquire);
    {
      std::lock_guard<PiMutex> lock(queueMutex_);
      writing_.swap(queue_);  // both reserved: the device thread's next copy needs no allocation
    }
    const bool written = writing_.empty() || writeOut(writing_);
    writing_.clear();
    if (!written) return;
    if (overflowed) {
      failWith(0);
      return;
    }
    if (stopping) return;
  }
}

bool RecordingWriter::writeOut(const std::string& data) {
  struct UnderWay {
    std::atomic<int>& count;
    explicit UnderWay(std::atomic<int>& c) : count(c) { count.fetch_add(1); }
    ~UnderWay() { count.fetch_sub(1); }
  } underWay(writesUnderWay_);
  // Sealed by a signal handler: its off record is the last line; the process is on its way out.
  if (sealed_.load()) return false;
  const int fd = fd_.load(std::memory_order_acquire);
  if (fd < 0) return false;
  int code = 0;
  if (!writeAll(fd, data.data(), data.size(), code)) {
    // Part of the chunk may be in the file: cut it back to the last whole line written.
    if (!truncateFile(fd, bytesWritten_)) {
    }
    failWith(code);
    return false;
  }
  bytesWritten_ += data.size();
  return true;
}

int RecordingWriter::sealFromSignal() {
  sealed_.store(true);
  spinUntilFromSignal([this] { return writesUnderWay_.load() == 0; }, 50000000);
  return fileDescriptor();
}

void RecordingWriter::failWith(int code) {
  errorCode_ = code;
  // The file is closed at once, so another recording may have it while the device, which
  // sees the failure at its next hand-over, goes on without one.
  closeFile();
  failed_.store(true, std::memory_order_release);
}

int RecordingWriter::closeFile() {
  const int fd = fd_.exchange(-1, std::memory_order_acq_rel);
  if (fd < 0) return 0;
  const int code = closeFileDescriptor(fd) == 0 ? 0 : errno;
  RecordingFiles& files = recordingFiles();
  std::lock_guard<std::mutex> lock(files.mutex);
  const std::pair<unsigned long long, unsigned long long> key{fileDevice_, fileInode_};
  files.keys.erase(std::remove(files.keys.begin(), files.keys.end(), key), files.keys.end());
  return code;
}

void RecordingWriter::finish() {
  if (writer_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(wakeMutex_);
      stopping_ = true;
    }
    wake_.notify_one();
    writer_.join();  // it writes what was queued first
  }
  const int code = closeFile();
  if (code != 0 && !failed()) closeError_ = "closing " + path_ + " failed (" + std::strerror(code) + ")";
}

std::string RecordingWriter::error() const {
  if (failed()) {
    if (errorCode_ == 0)
      return "writing " + path_ + " fell " + std::to_string(kQueueBytes >> 20) +
             " MiB behind (the disk is too slow); recording stopped, " + std::to_string(bytesWritten_) + " bytes kept";
    return "writing " + path_ + " failed (" + std::strerror(errorCode_) + "); recording stopped, " +
           std::to_string(bytesWritten_) + " bytes kept";
  }
  if (overflowed_.load(std::memory_order_acquire))
    return "writing " + path_ + " fell " + std::to_string(kQueueBytes >> 20) +
           " MiB behind (the disk is too slow); recording stopped";
  return closeError_;
}

}  // namespace kf
