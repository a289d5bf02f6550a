// LatencyHistogram: durations in 10 us bins up to 50 ms, written by one thread and read by
// any (relaxed atomics), for percentiles without allocation: the device thread's loop period,
// report-to-UGen and UGen-to-magnet latencies.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace kf {

class LatencyHistogram {
 public:
  static constexpr double kBinS = 10e-6;
  static constexpr int kBins = 5000;  // 50 ms; longer durations land in the last bin

  // One writer thread. Negative or NaN durations are ignored.
  void record(double durationS) {
    if (!(durationS >= 0.0)) return;
    const double bin = durationS / kBinS;
    const int index = bin >= kBins - 1 ? kBins - 1 : static_cast<int>(bin);
    bins_[index].fetch_add(1, std::memory_order_relaxed);
    count_.fetch_add(1, std::memory_order_relaxed);
    if (durationS > maxS_.load(std::memory_order_relaxed)) maxS_.store(durationS, std::memory_order_relaxed);
  }

  uint64_t count() const { return count_.load(std::memory_order_relaxed); }
  double maxS() const { return maxS_.load(std::memory_order_relaxed); }

  // The upper edge of the bin holding quantile q (0..1); 0 when empty.
  double quantileS(double q) const {
    const uint64_t total = count();
    if (total == 0) return 0.0;
    const double wanted = q * static_cast<double>(total);
    uint64_t seen = 0;
    for (int i = 0; i < kBins; ++i) {
      seen += bins_[i].load(std::memory_order_relaxed);
      if (static_cast<double>(seen) >= wanted) return (i + 1) * kBinS;
    }
    return kBins * kBinS;
  }

 private:
  std::array<std::atomic<uint32_t>, kBins> bins_{};
  std::atomic<uint64_t> count_{0};
  std::atomic<double> maxS_{0.0};
};

// p50, p99, p99.9 and max of a histogram, for snapshots.
struct LatencySummary {
  uint64_t count = 0;
  double p50S = 0.0, p99S = 0.0, maxS = 0.0, p999S = 0.0;
  static LatencySummary of(const LatencyHistogram& h) {
    return {h.count(), h.quantileS(0.50), h.quantileS(0.99), h.maxS(), h.quantileS(0.999)};
  }
};

}  // namespace kf
