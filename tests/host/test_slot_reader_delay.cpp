// The status's reader delay ("report to UGen", reportP50S/P99S/MaxS) is the wait of a report
// for a reader that is reading: the backlog a simulated device queues before its slot's first
// reader, or while its readers are all gone, is no reader's delay (it read 4192 ms on a fresh
// device before), while a reader that stalls (an audio thread late by 100 ms, its blocks
// consecutive) is exactly what the figure is for.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include "DeviceFactory.hpp"
#include "DeviceSlots.hpp"

using namespace kf;
using namespace kf::sc;
using namespace std::chrono_literals;

namespace {

constexpr int kSlot = 13;  // no other host test uses it
constexpr int kBlock = 64;
constexpr double kSampleDurS = 1.0 / 48000.0;

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Reads the slot as a UGen does, one block about every millisecond for durationS, from block on;
// returns the next block. lastRead: when the block before was read (nullopt: it was not), kept
// up to date; largestGapS: raised to the longest time between the reads of two consecutive blocks.
int64_t readBlocks(int64_t block, double durationS, std::optional<std::chrono::steady_clock::time_point>& lastRead,
                   double& largestGapS) {
  const auto start = std::chrono::steady_clock::now();
  while (secondsSince(start) < durationS) {
    const BlockClock clock{block, block * kBlock * kSampleDurS, kSampleDurS, kBlock};
    REQUIRE(viewSlot(kSlot, clock).device != nullptr);
    const auto now = std::chrono::steady_clock::now();
    if (lastRead) largestGapS = std::max(largestGapS, std::chrono::duration<double>(now - *lastRead).count());
    lastRead = now;
    ++block;
    std::this_thread::sleep_for(1ms);
  }
  return block;
}

}  // namespace

TEST_CASE("the reader delay counts from a reader on, and counts a reader that stalls") {
  constexpr double kNoReaderS = 0.3, kStallS = 0.1;
  std::string error;
  auto device = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::speeds({{50.0, 10.0}}), false, &error);
  REQUIRE(device);
  deleteRetired(exchangeSlot(kSlot, device.release()));

  // Reports queue with no reader for 0.3 s; then a reader reads.
  std::this_thread::sleep_for(std::chrono::duration<double>(kNoReaderS));
  std::optional<std::chrono::steady_clock::time_point> lastRead;
  double largestGapS = 0.0;
  int64_t block = readBlocks(0, 0.2, lastRead, largestGapS);
  // Every reader gone for 0.3 s (the server's blocks go on: block numbers jump), then back.
  std::this_thread::sleep_for(std::chrono::duration<double>(kNoReaderS));
  lastRead.reset();
  block = readBlocks(block + static_cast<int64_t>(kNoReaderS / (kBlock * kSampleDurS)), 0.2, lastRead, largestGapS);
  // The reader itself stalls for 0.1 s: its next block is the next one.
  std::this_thread::sleep_for(std::chrono::duration<double>(kStallS));
  readBlocks(block, 0.1, lastRead, largestGapS);

  const TelemetrySnapshot t = peekSlot(kSlot)->telemetry();
  const double reportIntervalS = 1.0 / DeviceSpec{}.updateRateHz;
  INFO("report to UGen max " << t.reportLatency.maxS * 1e3 << " ms (n " << t.reportLatency.count
                             << "), the reads' largest gap " << largestGapS * 1e3
                             << " ms, the device loop's longest period " << t.pumpPeriod.maxS * 1e3 << " ms");
  // A report stamped after a read is taken by the next one: its wait is at most the gap between
  // two reads of consecutive blocks (the stall's among them), plus the device thread's own delay between stamping and
  // queueing it (within one pump, so within the loop's longest period). The reports queued while nobody read waited 0.3
  // s, which the old figure counted.
  CHECK(t.reportLatency.maxS <= largestGapS + t.pumpPeriod.maxS);
  // The stall is counted: a report came within its first report interval (later by as much as
  // the device loop was late) and waited out the rest.
  CHECK(t.reportLatency.maxS >= kStallS - reportIntervalS - t.pumpPeriod.maxS);
  CHECK(t.reportLatency.count > 0);

  deleteRetired(exchangeSlot(kSlot, nullptr));
}
