// Telemetry: counters the device thread (and the audio side, for frame overflows) update and
// anyone may read, e.g. for kfStatus. Plain atomics, relaxed: each value is exact on its own,
// a snapshot of several is not a single instant.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>

#include "core/LatencyHistogram.hpp"
#include "core/threads/ThreadScheduling.hpp"

namespace kf {

struct TelemetrySnapshot {
  uint64_t reports = 0;
  double reportIntervalMeanS = 0.0;
  double reportIntervalJitterS = 0.0;  // standard deviation of the interval
  uint64_t reportQueueOverflows = 0;   // reports the audio side did not take in time
  uint64_t frameQueueOverflows = 0;    // force frames the device thread did not take in time
  uint64_t frames = 0;                 // force frames applied
  uint64_t watchdogTrips = 0;
  float lastCommandedForceN = 0.0f;
  uint64_t pumps = 0;
  LatencySummary pumpPeriod;     // realtime: the 1 kHz loop's period
  LatencySummary reportLatency;  // realtime: device thread takes a report -> a UGen takes it
  LatencySummary forceLatency;   // realtime: a frame's millisecond ends -> the magnet is told
  // Realtime jitter buffer: pumps, while frames flow, that released 0, 1, 2 or 3+ frames (one
  // per 1 ms pump is the goal); how far from its due time (start + latency) each frame went
  // out; the release latency now; frames released later than one period after due.
  uint64_t framesPerPump[4] = {0, 0, 0, 0};
  LatencySummary frameOffset;
  double releaseLatencyS = 0.0;
  uint64_t lateFrames = 0;
  // Realtime: 1 ms deadlines the device thread woke a whole period or more after (each
  // period counted), and frames it skipped rather than send stale in a burst after such a wake.
  uint64_t missedDeadlines = 0;
  uint64_t skippedFrames = 0;
  uint64_t orderlyOffs = 0;  // requestOff() carried out: the last writer went away
  // Realtime: the longest a FrictionOut's block held the audio thread (s): our own share of any
  // stall of the frames at their source, told apart from the server's and the machine's.
  double audioCallMaxS = 0.0;
  // How the device thread and the mouse's reader thread are scheduled (ThreadScheduling).
  ThreadScheduling deviceThread;
  ThreadScheduling mouseThread;
};

class Telemetry {
 public:
  // Device thread: one report with this deviceTimeS arrived.
  void countReport(double deviceTimeS);
  void countFrame(float commandedForceN);
  void setCommandedForce(float forceN) { lastCommandedForceN_.store(forceN, std::memory_order_relaxed); }
  void countWatchdogTrip() { watchdogTrips_.fetch_add(1, std::memory_order_relaxed); }
  void countPump() { pumps_.fetch_add(1, std::memory_order_relaxed); }

  // Each written by one thread: the device thread, the audio thread, the device thread.
  LatencyHistogram pumpPeriod;
  LatencyHistogram reportLatency;
  LatencyHistogram forceLatency;
  LatencyHistogram frameOffset;

  // Device thread: one pump released `count` frames while frames were flowing.
  void countReleases(int count) { framesPerPump_[count < 3 ? count : 3].fetch_add(1, std::memory_order_relaxed); }
  void countLateFrame() { lateFrames_.fetch_add(1, std::memory_order_relaxed); }
  void countMissedDeadlines(uint64_t count) { missedDeadlines_.fetch_add(count, std::memory_order_relaxed); }
  void countSkippedFrame() { skippedFrames_.fetch_add(1, std::memory_order_relaxed); }
  void countOrderlyOff() { orderlyOffs_.fetch_add(1, std::memory_order_relaxed); }
  void setReleaseLatency(double latencyS) { releaseLatencyS_.store(latencyS, std::memory_order_relaxed); }
  // Audio thread: one block of a FrictionOut took this long (a lock-free maximum).
  void recordAudioCall(double seconds) {
    double seen = audioCallMaxS_.load(std::memory_order_relaxed);
    while (seconds > seen && !audioCallMaxS_.compare_exchange_weak(seen, seconds, std::memory_order_relaxed)) {
    }
  }
  float commandedForceN() const { return lastCommandedForceN_.load(std::memory_order_relaxed); }

  // Queue overflow counts live in the queues; Device fills them in.
  TelemetrySnapshot snapshot() const;

 private:
  // Interval statistics (Welford), touched by the device thread only.
  double lastReportTimeS_ = 0.0;
  double intervalCount_ = 0.0;
  double intervalMeanS_ = 0.0;
  double intervalM2_ = 0.0;

  std::atomic<uint64_t> reports_{0};
  std::atomic<double> reportIntervalMeanS_{0.0};
  std::atomic<double> reportIntervalJitterS_{0.0};
  std::atomic<uint64_t> frames_{0};
  std::atomic<uint64_t> watchdogTrips_{0};
  std::atomic<float> lastCommandedForceN_{0.0f};
  std::atomic<uint64_t> pumps_{0};
  std::atomic<uint64_t> framesPerPump_[4] = {};
  std::atomic<uint64_t> lateFrames_{0};
  std::atomic<uint64_t> missedDeadlines_{0};
  std::atomic<uint64_t> skippedFrames_{0};
  std::atomic<uint64_t> orderlyOffs_{0};
  std::atomic<double> releaseLatencyS_{0.0};
  std::atomic<double> audioCallMaxS_{0.0};
};

inline void Telemetry::countReport(double deviceTimeS) {
  const uint64_t count = reports_.fetch_add(1, std::memory_order_relaxed) + 1;
  if (count > 1) {
    const double intervalS = deviceTimeS - lastReportTimeS_;
    intervalCount_ += 1.0;
    const double delta = intervalS - intervalMeanS_;
    intervalMeanS_ += delta / intervalCount_;
    intervalM2_ += delta * (intervalS - intervalMeanS_);
    reportIntervalMeanS_.store(intervalMeanS_, std::memory_order_relaxed);
    reportIntervalJitterS_.store(std::sqrt(intervalM2_ / intervalCount_), std::memory_order_relaxed);
  }
  lastReportTimeS_ = deviceTimeS;
}

inline void Telemetry::countFrame(float commandedForceN) {
  frames_.fetch_add(1, std::memory_order_relaxed);
  setCommandedForce(commandedForceN);
}

inline TelemetrySnapshot Telemetry::snapshot() const {
  TelemetrySnapshot s;
  s.reports = reports_.load(std::memory_order_relaxed);
  s.reportIntervalMeanS = reportIntervalMeanS_.load(std::memory_order_relaxed);
  s.reportIntervalJitterS = reportIntervalJitterS_.load(std::memory_order_relaxed);
  s.frames = frames_.load(std::memory_order_relaxed);
  s.watchdogTrips = watchdogTrips_.load(std::memory_order_relaxed);
  s.lastCommandedForceN = lastCommandedForceN_.load(std::memory_order_relaxed);
  s.pumps = pumps_.load(std::memory_order_relaxed);
  s.pumpPeriod = LatencySummary::of(pumpPeriod);
  s.reportLatency = LatencySummary::of(reportLatency);
  s.forceLatency = LatencySummary::of(forceLatency);
  for (int i = 0; i < 4; ++i) s.framesPerPump[i] = framesPerPump_[i].load(std::memory_order_relaxed);
  s.frameOffset = LatencySummary::of(frameOffset);
  s.releaseLatencyS = releaseLatencyS_.load(std::memory_order_relaxed);
  s.lateFrames = lateFrames_.load(std::memory_order_relaxed);
  s.missedDeadlines = missedDeadlines_.load(std::memory_order_relaxed);
  s.skippedFrames = skippedFrames_.load(std::memory_order_relaxed);
  s.orderlyOffs = orderlyOffs_.load(std::memory_order_relaxed);
  s.audioCallMaxS = audioCallMaxS_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace kf
