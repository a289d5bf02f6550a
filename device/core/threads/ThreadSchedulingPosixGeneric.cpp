// ThreadScheduling's calls on a POSIX system other than Linux (macOS; KF_PLATFORM=posix): no
// clock_nanosleep there, so deadlines are std::this_thread::sleep_until on steady_clock, which
// libc++ sleeps to by the remaining time (a wake-up's lateness still does not add to the next
// deadline, as the grid is kept by the caller). Priority through pthread_getschedparam.
#include <pthread.h>
#include <sched.h>

#include <thread>

#include "core/threads/ThreadScheduling.hpp"
#include "core/threads/ThreadSchedulingPosix.hpp"

namespace kf {

void nameThisThread(const char* name) {
#ifdef __APPLE__
  ::pthread_setname_np(name);  // Apple's names only the calling thread
#else
  ::pthread_setname_np(::pthread_self(), name);
#endif
}

int currentThreadPriority() {
  int policy = 0;
  sched_param param{};
  if (::pthread_getschedparam(::pthread_self(), &policy, &param) != 0) return 0;
  return policy == SCHED_FIFO || policy == SCHED_RR ? param.sched_priority : 0;
}

void sleepUntil(std::chrono::steady_clock::time_point deadline) { std::this_thread::sleep_until(deadline); }

}  // namespace kf
