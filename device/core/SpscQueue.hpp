// SpscQueue: fixed-capacity lock-free queue between exactly one producer thread and one
// consumer thread (device thread <-> audio thread). push/pop never allocate, lock or wait;
// a push into a full queue is dropped and counted.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace kf {

template <typename T>
class SpscQueue {
 public:
  // Allocates once, here; holds up to `capacity` items.
  explicit SpscQueue(size_t capacity) : slotCount_(capacity + 1), slots_(std::make_unique<T[]>(capacity + 1)) {}

  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  // Producer only.
  bool push(const T& item) {
    const size_t tail = tail_.load(std::memory_order_relaxed);
    const size_t next = tail + 1 == slotCount_ ? 0 : tail + 1;
    if (next == head_.load(std::memory_order_acquire)) {
      overflows_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slots_[tail] = item;
    tail_.store(next, std::memory_order_release);
    return true;
  }

  // Consumer only.
  bool pop(T& item) {
    const size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return false;
    item = slots_[head];
    head_.store(head + 1 == slotCount_ ? 0 : head + 1, std::memory_order_release);
    return true;
  }

  size_t capacity() const { return slotCount_ - 1; }
  // Any thread; exact only when the other side is idle.
  size_t sizeApprox() const {
    const size_t head = head_.load(std::memory_order_acquire);
    const size_t tail = tail_.load(std::memory_order_acquire);
    return tail >= head ? tail - head : tail + slotCount_ - head;
  }
  uint64_t overflows() const { return overflows_.load(std::memory_order_relaxed); }
  // The slots' memory (to lock it: ThreadScheduling's lockMemory).
  const void* storage() const { return slots_.get(); }
  size_t storageBytes() const { return slotCount_ * sizeof(T); }

 private:
  const size_t slotCount_;  // one slot stays free to tell full from empty
  std::unique_ptr<T[]> slots_;
  alignas(64) std::atomic<size_t> head_{0};  // next to pop
  alignas(64) std::atomic<size_t> tail_{0};  // next to push
  alignas(64) std::atomic<uint64_t> overflows_{0};
};

}  // namespace kf
