// RecordingWriter: the file of one recording — a regular file that no other recording of this
// process writes — and the writes into it. Threaded (a realtime device), the device thread hands
// whole lines over under a priority-inheriting lock held for one copy, and a writer thread of
// normal priority (kf-rec-<slot>) writes them every 10 ms: a slow, full or stalled disk never
// holds up the force path. Direct (lockstep: NRT renders, tests), the lines are written at once
// by the caller, so the file is complete after every hand-over.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "core/threads/PiMutex.hpp"

namespace kf {

class RecordingWriter {
 public:
  // How far the disk may fall behind a threaded recording before the recording stops: 4 MiB,
  // about 30 s of a 1 kHz device's reports and frames. Reserved at open, so a hand-over never
  // allocates.
  static constexpr size_t kQueueBytes = size_t(4) << 20;
  static constexpr int kWritePeriodMs = 10;

  // Opens `path` for a recording and writes `header` at once, so that a file that cannot take
  // even that is refused here. Refuses what is not a regular file (a FIFO would block, a
  // device is no recording) and a file another recording of this process writes (under any
  // path); truncates only then. Null and `error` when refused.
  static std::unique_ptr<RecordingWriter> open(const std::string& path, const std::string& header, bool threaded,
                                               int slot, std::string& error);
  ~RecordingWriter() { finish(); }
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  // The recording thread's side: `lines` (whole lines) go to the file (direct) or the writer's
  // queue (threaded) and are cleared. False once the recording has failed: a write error, or
  // (threaded) the disk fell kQueueBytes behind. Never allocates when threaded.
  bool hand(std::string& lines);
  // Writes what was handed, stops the writer thread, closes the file and lets another recording
  // have it. Idempotent. Blocks for the last writes: never from the device thread while it
  // records, never under the device's state lock.
  void finish();

  bool failed() const { return failed_.load(std::memory_order_acquire); }
  // Why the recording stopped by itself (once failed()), or why closing failed; else empty.
  std::string error() const;
  // For signal handlers (async-signal-safe): the file descriptor, -1 once closed.
  int fileDescriptor() const { return fd_.load(std::memory_order_acquire); }
  // For signal handlers (async-signal-safe), before the off record: no write starts after this,
  // and one under way is waited for, at most 50 ms (the handler may be running on the writing
  // thread itself), so the off record is the file's last line. Returns fileDescriptor().
  int sealFromSignal();

 private:
  RecordingWriter(int fd, std::string path, unsigned long long fileDevice, unsigned long long fileInode);
  void writerLoop(int slot);
  // Writes `data`; on an error, cuts the file back to its last whole line, closes it and fails.
  bool writeOut(const std::string& data);
  void failWith(int code);
  // Closes the file and lets another recording have it; the close's errno, or 0.
  int closeFile();

  std::atomic<int> fd_{-1};
  // sealFromSignal() and the writes it waits for (sequentially consistent, so that a write sees
  // the seal or the seal sees the write: never neither).
  std::atomic<bool> sealed_{false};
  std::atomic<int> writesUnderWay_{0};
  const std::string path_;
  const unsigned long long fileDevice_, fileInode_;  // the key of "one recording per file"
  uint64_t bytesWritten_ = 0;                        // by whoever writes: the caller or the writer

  // Threaded only.
  PiMutex queueMutex_;
  std::string queue_;                    // handed over, not yet written (queueMutex_)
  std::string writing_;                  // the writer thread's: being written
  std::atomic<bool> overflowed_{false};  // a hand-over found the queue full
  std::thread writer_;
  std::mutex wakeMutex_;
  std::condition_variable wake_;
  bool stopping_ = false;  // wakeMutex_

  std::atomic<bool> failed_{false};
  int errorCode_ = 0;       // set before failed_ (release); 0 with failed_: the disk fell behind
  std::string closeError_;  // finish()'s, read after it
};

}  // namespace kf
