// The parts of ThreadScheduling that are the same on every system: the audio thread's priority
// as noted, the priority a request resolves to, and the description status posts. What asks the
// system lives in one file per platform (ThreadSchedulingPosix/-Linux/-PosixGeneric/-Windows.cpp,
// chosen in CMake by KF_PLATFORM).
#include "core/threads/ThreadScheduling.hpp"

#include <algorithm>

namespace kf {

namespace {
std::atomic<int> gAudioPriority{-1};
}  // namespace

void noteAudioThreadPriority(int priority) { gAudioPriority.store(priority, std::memory_order_relaxed); }

int audioThreadPriority() { return gAudioPriority.load(std::memory_order_relaxed); }

int resolvePriority(int requested) {
  if (requested != kAutoPriority) return std::clamp(requested, kNormalPriority, kMaxPriority);
  const int audio = audioThreadPriority();
  return audio > 0 ? std::min(audio + 1, kMaxPriority) : kFallbackPriority;
}

// Not inlined: its frame must lie below the caller's. Written, so that the pages are mapped.
__attribute__((noinline)) bool lockStackBelow() {
  constexpr size_t kBytes = 64 * 1024;  // the device pump's calls need a few kB
  volatile char stack[kBytes];
  for (size_t i = 0; i < kBytes; i += 256) stack[i] = 0;
  return lockMemory(const_cast<char*>(stack), kBytes);
}

std::string describe(const ThreadScheduling& s) {
  if (s.priority < 0) return "not started";
  std::string text = s.priority > 0 ? realtimeSchedulingName(s.priority) : std::string("normal priority");
  return text + (s.memoryLocked ? ", memory locked" : "");
}

}  // namespace kf
