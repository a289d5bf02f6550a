// ThreadScheduling on every POSIX system (Linux, macOS): SCHED_FIFO through pthread, memory
// locked with mlock, signals blocked for new threads, the monotonic clock in a signal handler.
// The calls that differ between them are in ThreadSchedulingLinux.cpp and
// ThreadSchedulingPosixGeneric.cpp.
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "core/threads/DeviceMessages.hpp"
#include "core/threads/ThreadScheduling.hpp"
#include "core/threads/ThreadSchedulingPosix.hpp"

namespace kf {

namespace {

std::atomic<bool> gRefusalPosted{false};

void postRefusalOnce(const char* name, int priority, int error) {
  if (gRefusalPosted.exchange(true)) return;
  char message[640];
  std::snprintf(
      message, sizeof(message),
      "KineticFriction: realtime scheduling (SCHED_FIFO %d) refused for %s (%s): the device threads run at "
      "normal priority, so a busy machine can delay force frames and mouse reports by tens of ms. On Linux, "
      "grant it as for JACK: put the user in the 'audio' group with '@audio - rtprio 95' and '@audio - memlock "
      "unlimited' in /etc/security/limits.d/audio.conf and log in again (a systemd service: "
      "LimitRTPRIO=95, LimitMEMLOCK=infinity).",
      priority, name, std::strerror(error));
  postDeviceMessage(message);
}

}  // namespace

std::string realtimeSchedulingName(int priority) { return "SCHED_FIFO " + std::to_string(priority); }

bool lockMemory(const void* data, size_t bytes) {
  if (data == nullptr || bytes == 0) return true;
  const uintptr_t page = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
  const uintptr_t start = reinterpret_cast<uintptr_t>(data) & ~(page - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(data) + bytes;
  return ::mlock(reinterpret_cast<const void*>(start), end - start) == 0;
}

ThreadScheduling scheduleThisThread(const char* role, const ThreadRequest& request) {
  char name[16];  // the kernel keeps 15 characters
  std::snprintf(name, sizeof(name), "kf-%s-%d", role, request.slot);
  nameThisThread(name);
  ThreadScheduling got;
  const int priority = resolvePriority(request.priority);
  sched_param param{};
  if (priority == kNormalPriority) {
    // Asked for explicitly: a thread inherits its creator's policy (scsynth's command thread
    // may be realtime), and lowering is always allowed.
    ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &param);
  } else {
    // Within the system's SCHED_FIFO range: Linux's 1..99 holds every priority we ask for, but
    // other systems have narrower ones (macOS: 15..47), where a priority outside it is refused.
    // Not testable here (Linux); the libc++ build compiles this path.
    param.sched_priority =
        std::clamp(priority, ::sched_get_priority_min(SCHED_FIFO), ::sched_get_priority_max(SCHED_FIFO));
    if (const int error = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param); error != 0)
      postRefusalOnce(name, param.sched_priority, error);
    got.memoryLocked = lockStackBelow();
  }
  got.priority = currentThreadPriority();  // what it has, inherited or not
  return got;
}

std::thread startThreadWithAsyncSignalsBlocked(std::function<void()> work) {
  sigset_t blocked, previous;
  sigfillset(&blocked);
  for (int fault : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTRAP, SIGSYS}) sigdelset(&blocked, fault);
  pthread_sigmask(SIG_BLOCK, &blocked, &previous);
  std::thread thread;
  try {
    thread = std::thread(std::move(work));
  } catch (...) {  // no thread: the caller (a command's NRT thread) gets its own mask back
    pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    throw;
  }
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return thread;
}

int64_t monotonicNanosecondsFromSignal() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<int64_t>(now.tv_sec) * 1000000000 + now.tv_nsec;
}

}  // namespace kf
