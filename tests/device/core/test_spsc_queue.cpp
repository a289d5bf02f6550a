#include <atomic>
#include <catch2/catch.hpp>
#include <cstdint>
#include <thread>

#include "core/SpscQueue.hpp"

using namespace kf;

TEST_CASE("queue keeps order and counts overflow", "[queue]") {
  SpscQueue<int> queue(4);
  CHECK(queue.capacity() == 4);
  int value = -1;
  CHECK_FALSE(queue.pop(value));
  for (int i = 0; i < 6; ++i) CHECK(queue.push(i) == (i < 4));
  CHECK(queue.overflows() == 2);
  CHECK(queue.sizeApprox() == 4);
  for (int i = 0; i < 4; ++i) {
    REQUIRE(queue.pop(value));
    CHECK(value == i);
  }
  CHECK_FALSE(queue.pop(value));
  // Wraps around.
  for (int round = 0; round < 10; ++round) {
    for (int i = 0; i < 3; ++i) REQUIRE(queue.push(round * 10 + i));
    for (int i = 0; i < 3; ++i) {
      REQUIRE(queue.pop(value));
      CHECK(value == round * 10 + i);
    }
  }
  CHECK(queue.overflows() == 2);
}

// The ThreadSanitizer build runs this test too, with fewer items (it is ~20x slower there).
#ifndef KF_QUEUE_STRESS_ITEMS
#define KF_QUEUE_STRESS_ITEMS 2000000
#endif

TEST_CASE("queue under two threads delivers every item in order", "[queue]") {
  constexpr uint64_t kItems = KF_QUEUE_STRESS_ITEMS;
  SpscQueue<uint64_t> queue(64);
  std::thread producer([&] {
    for (uint64_t i = 0; i < kItems; ++i)
      while (!queue.push(i)) std::this_thread::yield();
  });
  uint64_t expected = 0;
  bool inOrder = true;
  while (expected < kItems) {
    uint64_t value = 0;
    if (queue.pop(value)) {
      inOrder = inOrder && value == expected;
      ++expected;
    }
  }
  producer.join();
  CHECK(inOrder);
  CHECK(expected == kItems);
  uint64_t extra = 0;
  CHECK_FALSE(queue.pop(extra));
}
