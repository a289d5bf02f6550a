// A bounded wait for the device tests: a thread's pace is the machine's, so a test waits for what
// it needs rather than for a fixed time.
#pragma once

#include <chrono>
#include <thread>

namespace kf::test {

// Waits until `done` holds; false after `limit` (which only a failing test reaches).
template <class Done>
bool waitFor(Done done, std::chrono::milliseconds limit = std::chrono::milliseconds(3000)) {
  const auto start = std::chrono::steady_clock::now();
  while (!done()) {
    if (std::chrono::steady_clock::now() - start > limit) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace kf::test
