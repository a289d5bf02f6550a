// ThreadScheduling's Linux calls: the thread's name as the kernel keeps it, the calling thread's
// priority by straight system calls, and absolute deadlines with clock_nanosleep.
#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <cerrno>

#include "core/threads/ThreadScheduling.hpp"
#include "core/threads/ThreadSchedulingPosix.hpp"

namespace kf {

void nameThisThread(const char* name) { ::pthread_setname_np(::pthread_self(), name); }

int currentThreadPriority() {
  // sched_get*(0) are the calling thread's, straight system calls (pthread_getschedparam would
  // take the thread descriptor's lock).
  const int policy = ::sched_getscheduler(0);
  sched_param param{};
  if ((policy != SCHED_FIFO && policy != SCHED_RR) || ::sched_getparam(0, &param) != 0) return 0;
  return param.sched_priority;
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

}  // namespace kf
