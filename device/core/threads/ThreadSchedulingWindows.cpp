// ThreadScheduling on Windows: the thread's name through SetThreadDescription (debuggers and
// Process Explorer show it), realtime as THREAD_PRIORITY_TIME_CRITICAL (the highest a thread of
// a normal-class process gets; scsynth's audio thread is at that level too, so there is no "one
// above"), memory locked with VirtualLock. Deadlines: std::this_thread::sleep_until, whose
// wake-up is only as fine as the system timer: 15.6 ms unless the process asks for 1 ms
// (timeBeginPeriod; since Windows 10 2004 another process's request no longer applies to ours),
// which the first realtime thread does, for the process's life. Nothing here is tested on
// Windows itself: the suites run under Wine (scripts/check.sh cross), which does not schedule
// as Windows does.
#include <windows.h>
// After windows.h, which it needs.
#include <timeapi.h>

#include <atomic>
#include <cstdio>
#include <cwchar>

#include "core/threads/DeviceMessages.hpp"
#include "core/threads/ThreadScheduling.hpp"

namespace kf {

namespace {

std::atomic<bool> gRefusalPosted{false};

// SetThreadDescription is Windows 10 1607's: looked up, so that older systems load the plugin.
void nameThisThread(const char* name) {
  using SetDescription = HRESULT(WINAPI*)(HANDLE, PCWSTR);
  const FARPROC found = ::GetProcAddress(::GetModuleHandleW(L"kernel32.dll"), "SetThreadDescription");
  if (found == nullptr) return;
  wchar_t wideName[16];
  std::swprintf(wideName, 16, L"%hs", name);
  reinterpret_cast<SetDescription>(reinterpret_cast<void*>(found))(::GetCurrentThread(), wideName);
}

}  // namespace

int currentThreadPriority() {
  // Windows has no priority numbers like SCHED_FIFO's: time-critical reads as the highest.
  return ::GetThreadPriority(::GetCurrentThread()) >= THREAD_PRIORITY_TIME_CRITICAL ? kMaxPriority : 0;
}

std::string realtimeSchedulingName(int) { return "time-critical"; }

bool lockMemory(const void* data, size_t bytes) {
  if (data == nullptr || bytes == 0) return true;
  return ::VirtualLock(const_cast<void*>(data), bytes) != 0;
}

ThreadScheduling scheduleThisThread(const char* role, const ThreadRequest& request) {
  char name[16];
  std::snprintf(name, sizeof(name), "kf-%s-%d", role, request.slot);
  nameThisThread(name);
  ThreadScheduling got;
  const int priority = resolvePriority(request.priority);
  if (priority == kNormalPriority) {
    ::SetThreadPriority(::GetCurrentThread(), THREAD_PRIORITY_NORMAL);
  } else {
    static const bool fineTimer = ::timeBeginPeriod(1) == TIMERR_NOERROR;  // once per process, never ended
    (void)fineTimer;
    if (!::SetThreadPriority(::GetCurrentThread(), THREAD_PRIORITY_TIME_CRITICAL) && !gRefusalPosted.exchange(true)) {
      char message[200];
      std::snprintf(message, sizeof(message),
                    "KineticFriction: time-critical priority refused for %s (error %lu): the device threads run "
                    "at normal priority.",
                    name, static_cast<unsigned long>(::GetLastError()));
      postDeviceMessage(message);
    }
    got.memoryLocked = lockStackBelow();
  }
  got.priority = currentThreadPriority();
  return got;
}

void sleepUntil(std::chrono::steady_clock::time_point deadline) { std::this_thread::sleep_until(deadline); }

std::thread startThreadWithAsyncSignalsBlocked(std::function<void()> work) { return std::thread(std::move(work)); }

int64_t monotonicNanosecondsFromSignal() {
  LARGE_INTEGER counter, frequency;
  ::QueryPerformanceCounter(&counter);
  ::QueryPerformanceFrequency(&frequency);
  return static_cast<int64_t>(static_cast<double>(counter.QuadPart) * 1e9 / static_cast<double>(frequency.QuadPart));
}

}  // namespace kf
