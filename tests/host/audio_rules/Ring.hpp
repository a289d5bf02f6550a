// A fixed-capacity ring between exactly one producer thread and one consumer thread: what the
// harness hands to or from its audio thread goes through these, so that the harness itself never
// allocates, locks or waits there (scsynth's MsgFifo is the same kind of queue).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>

namespace kf::rules {

template <typename T, std::size_t N>
class Ring {
 public:
  // False when full: the item is not taken.
  bool push(const T& item) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t next = (tail + 1) % N;
    if (next == head_.load(std::memory_order_acquire)) return false;
    items_[tail] = item;
    tail_.store(next, std::memory_order_release);
    return true;
  }

  bool pop(T& item) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return false;
    item = items_[head];
    head_.store((head + 1) % N, std::memory_order_release);
    return true;
  }

 private:
  std::array<T, N> items_{};
  std::atomic<std::size_t> head_{0};
  std::atomic<std::size_t> tail_{0};
};

}  // namespace kf::rules
