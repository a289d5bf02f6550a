// A bounded wait for the device tests: a thread's pace is the machine's, so a test waits for what
// it needs rather than for a fixed time.
#pragma once

#include <chrono>
#include <thread>

namespace kf::test {

// Waits until `done` holds; false after `limit` (which only a failing test reaches), counted in
// this thread's own 1 ms sleeps, not on the clock: a machine that stands still passes the clock
// beyond any limit before the thread waited for has run again (two test commands side by side,
// fresh clone 92: 74 s).
template <class Done>
bool waitFor(Done done, std::chrono::milliseconds limit = std::chrono::milliseconds(3000)) {
  for (long slept = 0; !done(); ++slept) {
    if (slept > limit.count()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace kf::test
