// ThreadScheduling: how a thread of ours with a deadline (the device thread, a mouse reader, the
// USB event thread) asks to run as a realtime citizen, as JACK's and scsynth's audio threads do:
// a name that ps -L and top -H show (kf-device-0), SCHED_FIFO at a priority chosen relative to
// the audio thread, memory locked. Where the system refuses, the thread runs on at normal
// priority and one message per process says how to grant it. Never a reason to fail an open.
// The calls to the system are in one file per platform (ThreadSchedulingPosix.cpp with
// ThreadSchedulingLinux.cpp or ThreadSchedulingPosixGeneric.cpp; ThreadSchedulingWindows.cpp).
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>

namespace kf {

// A thread's requested priority: kAutoPriority chooses one above the audio thread (see
// resolvePriority), kNormalPriority asks for nothing (SCHED_OTHER), 1..kMaxPriority SCHED_FIFO.
constexpr int kAutoPriority = -1;
constexpr int kNormalPriority = 0;
constexpr int kMaxPriority = 98;  // 99 is left to the kernel's own watchdog threads

struct ThreadRequest {
  int slot = 0;                  // the device slot: part of the thread's name
  int priority = kAutoPriority;  // as above
};

// What a thread got: priority -1 before it started, 0 normal scheduling, > 0 SCHED_FIFO; and
// whether its stack (and, for the device thread, the device's memory) is locked in RAM.
struct ThreadScheduling {
  int priority = -1;
  bool memoryLocked = false;
};

// Written once by the thread it describes, read by status from any thread.
class ThreadSchedulingCell {
 public:
  void store(const ThreadScheduling& s) {
    memoryLocked_.store(s.memoryLocked, std::memory_order_relaxed);
    priority_.store(s.priority, std::memory_order_release);
  }
  ThreadScheduling load() const {
    return {priority_.load(std::memory_order_acquire), memoryLocked_.load(std::memory_order_relaxed)};
  }

 private:
  std::atomic<int> priority_{-1};
  std::atomic<bool> memoryLocked_{false};
};

// The audio thread's SCHED_FIFO priority (0: not realtime), noted by the host from the audio
// thread itself (noteAudioThreadPriority(currentThreadPriority())); -1 while unknown.
void noteAudioThreadPriority(int priority);
int audioThreadPriority();
// The calling thread's SCHED_FIFO/SCHED_RR priority, 0 for any other policy. No lock, no
// allocation: two system calls on the calling thread (the audio thread may call it).
int currentThreadPriority();

// kAutoPriority: one above the audio thread when that is realtime (our threads' work is a few
// microseconds a wake-up and their deadline, a 1 ms frame, is no longer than an audio period;
// JACK runs its own server thread above its clients for the same reason), else
// kFallbackPriority; others as given, within 0..kMaxPriority.
constexpr int kFallbackPriority = 10;
int resolvePriority(int requested);

// Locks `bytes` of memory at `data` in RAM (mlock) where the memlock limit or CAP_IPC_LOCK allows
// it, so that a device's state and queues never page out; false where refused. Only the
// device's own memory: mlockall would fault in and pin the whole server (scsynth maps about a
// gigabyte) and hold every other thread's page faults up meanwhile, the audio thread's too.
bool lockMemory(const void* data, size_t bytes);
// For scheduleThisThread on every system: faults in and locks the 64 kB of stack below the
// caller, where the thread's work will run.
bool lockStackBelow();

// Called by the thread itself as it starts: names it "kf-<role>-<slot>", asks SCHED_FIFO at
// resolvePriority(request.priority) (kNormalPriority sets SCHED_OTHER), and with realtime
// faults in and locks the stack its work will use (memoryLocked). A refusal posts one message per
// process (postDeviceMessage) naming the fix.
ThreadScheduling scheduleThisThread(const char* role, const ThreadRequest& request);

// Sleeps until `deadline` on the monotonic clock, as an absolute deadline (clock_nanosleep
// TIMER_ABSTIME): a wake-up's lateness does not add to the next one's.
void sleepUntil(std::chrono::steady_clock::time_point deadline);

// A thread running `work`, born with every asynchronous signal blocked (a thread inherits its
// creator's mask), so that no signal meant for the process (SIGINT, SIGCHLD, a profiler's
// SIGPROF) is handled on it: a blocking read there would return EINTR, which reads as an
// unplug. The faults a thread causes itself stay unblocked, so a crash still reaches the exit
// handlers (host/ExitSafety) that drive the magnet off. Where there are no signals (Windows), a
// plain std::thread.
std::thread startThreadWithAsyncSignalsBlocked(std::function<void()> work);

// The monotonic clock in ns, callable from a signal handler (async-signal-safe).
int64_t monotonicNanosecondsFromSignal();

// Async-signal-safe: spins until done() or timeoutNs on the monotonic clock, for the exit paths
// that wait on another thread's work and may be running on that very thread. False on timeout.
template <class Done>
bool spinUntilFromSignal(Done done, int64_t timeoutNs) {
  const int64_t startNs = monotonicNanosecondsFromSignal();
  while (!done())
    if (monotonicNanosecondsFromSignal() - startNs > timeoutNs) return false;
  return true;
}

// "SCHED_FIFO 66, memory locked" / "normal priority (realtime refused)" / "not started"; on
// Windows "time-critical" for the realtime class.
std::string describe(const ThreadScheduling& s);
// What realtime scheduling at `priority` (> 0) is called here: "SCHED_FIFO 66" (POSIX),
// "time-critical" (Windows, which has one realtime level, not numbers).
std::string realtimeSchedulingName(int priority);

}  // namespace kf
