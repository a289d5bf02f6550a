#include "core/threads/ThreadScheduling.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>

#include "core/threads/DeviceMessages.hpp"

namespace kf {

namespace {

std::atomic<int> gAudioPriority{-1};
std::atomic<bool> gRefusalPosted{false};

void postRefusalOnce(const char* name, int priority, int error) {
  if (gRefusalPosted.exchange(true)) return;
  char message[640];
  std::snprintf(message, sizeof(message),
                "KineticFriction: realtime scheduling (SCHED_FIFO %d) refused for %s (%s): the device threads run at "
                "normal priority, so a busy machine can delay force frames and mouse reports by tens of ms. Grant it "
                "as for JACK: put the user in the 'audio' group with '@audio - rtprio 95' and '@audio - memlock "
                "unlimited' in /etc/security/limits.d/audio.conf and log in again (a systemd service: "
                "LimitRTPRIO=95, LimitMEMLOCK=infinity).",
                priority, name, std::strerror(error));
  postDeviceMessage(message);
}

}  // namespace

void noteAudioThreadPriority(int priority) { gAudioPriority.store(priority, std::memory_order_relaxed); }

int audioThreadPriority() { return gAudioPriority.load(std::memory_order_relaxed); }

int currentThreadPriority() {
  // sched_get*(0) are the calling thread's, straight system calls (pthread_getschedparam would
  // take the thread descriptor's lock).
  const int policy = ::sched_getscheduler(0);
  sched_param param{};
  if ((policy != SCHED_FIFO && policy != SCHED_RR) || ::sched_getparam(0, &param) != 0) return 0;
  return param.sched_priority;
}

int resolvePriority(int requested) {
  if (requested != kAutoPriority) return std::clamp(requested, kNormalPriority, kMaxPriority);
  const int audio = audioThreadPriority();
  return audio > 0 ? std::min(audio + 1, kMaxPriority) : kFallbackPriority;
}

bool lockMemory(const void* data, size_t bytes) {
  if (data == nullptr || bytes == 0) return true;
  const uintptr_t page = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
  const uintptr_t start = reinterpret_cast<uintptr_t>(data) & ~(page - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(data) + bytes;
  return ::mlock(reinterpret_cast<const void*>(start), end - start) == 0;
}

namespace {

// The stack below the caller, where the thread's work will run: written (so that it is mapped)
// and locked. Not inlined: its frame must lie below the caller's.
__attribute__((noinline)) bool lockStackBelow() {
  constexpr size_t kBytes = 64 * 1024;  // the device pump's calls need a few kB
  volatile char stack[kBytes];
  for (size_t i = 0; i < kBytes; i += 256) stack[i] = 0;
  return lockMemory(const_cast<char*>(stack), kBytes);
}

}  // namespace

ThreadScheduling scheduleThisThread(const char* role, const ThreadRequest& request) {
  char name[16];  // the kernel keeps 15 characters
  std::snprintf(name, sizeof(name), "kf-%s-%d", role, request.slot);
  ::pthread_setname_np(::pthread_self(), name);
  ThreadScheduling got;
  const int priority = resolvePriority(request.priority);
  sched_param param{};
  if (priority == kNormalPriority) {
    // Asked for explicitly: a thread inherits its creator's policy (scsynth's command thread
    // may be realtime), and lowering is always allowed.
    ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &param);
  } else {
    param.sched_priority = priority;
    if (const int error = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param); error != 0)
      postRefusalOnce(name, priority, error);
    got.memoryLocked = lockStackBelow();
  }
  got.priority = currentThreadPriority();  // what it has, inherited or not
  return got;
}

void sleepUntil(std::chrono::steady_clock::time_point deadline) {
  // libstdc++'s steady_clock is CLOCK_MONOTONIC on Linux.
  const auto sinceEpoch = deadline.time_since_epoch();
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(sinceEpoch);
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(seconds.count());
  ts.tv_nsec = static_cast<long>(std::chrono::duration_cast<std::chrono::nanoseconds>(sinceEpoch - seconds).count());
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

std::string describe(const ThreadScheduling& s) {
  if (s.priority < 0) return "not started";
  std::string text = s.priority > 0 ? "SCHED_FIFO " + std::to_string(s.priority) : std::string("normal priority");
  return text + (s.memoryLocked ? ", memory locked" : "");
}

}  // namespace kf
