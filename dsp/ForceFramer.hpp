// ForceFramer: audio-rate force (N) -> one mean force per frame (1 ms by default), the unit in
// which the paper's system programs friction ("durations down to 1 ms").
//
// Frames are aligned on audio time: frame k covers [k * P, (k + 1) * P). Each sample is
// taken as constant over its own duration [t, t + sampleDur) and weighted by the part of that
// duration inside the frame, so a frame's value is the exact mean of the held signal even
// when a frame is not a whole number of samples (44.1 samples at 44.1 kHz). Boundaries are
// computed from the caller's block start time and k * P in double, never by accumulating P,
// so nothing drifts over long runs.
//
// NaN/Inf samples count as minForceN (magnet off is the safe value); each frame's mean is
// clamped to [minForceN, maxForceN]. Nothing here allocates.
#pragma once

#include <cstdint>

#include "PaperProfile.hpp"

namespace kf {

class ForceFramer {
 public:
  // Receives each completed frame: its start time (audio seconds) and clamped mean force.
  using FrameSink = void (*)(void* context, double frameTimeS, float forceN);

  ForceFramer(double framePeriodS = paper::device::forceFramePeriodS, double minForceN = paper::device::minForceN,
              double maxForceN = paper::device::maxForceN);

  void setForceRange(double minForceN, double maxForceN);
  // Forgets the frame in progress and the last commanded value (back to minForceN).
  void reset();
  // Forgets the frame in progress (its samples are never sent), keeping the last commanded
  // value and the count of frames; the next block opens the frame of its own first sample.
  void dropFrameInProgress();

  // One block: sample i starts at blockStartTimeS + i * sampleDurS. commandedN (may be null)
  // receives per sample the last completed frame's value as known after that sample. Returns
  // the number of frames completed. A block that does not start where the previous one ended
  // (more than half a sample off) first closes the frame in progress with what it has.
  int process(double blockStartTimeS, double sampleDurS, const float* forceN, int numSamples, float* commandedN,
              FrameSink sink, void* context);

  // The same with any callable sink(double frameTimeS, float forceN).
  template <class Sink>
  int process(double blockStartTimeS, double sampleDurS, const float* forceN, int numSamples, float* commandedN,
              Sink& sink) {
    return process(blockStartTimeS, sampleDurS, forceN, numSamples, commandedN, &ForceFramer::callSink<Sink>, &sink);
  }

  // From inside a sink: the value shown in commandedN from the completing sample on is
  // `forceN` (what the device really commanded) instead of the frame's mean.
  void showCommanded(float forceN) { lastCommandedN_ = forceN; }

  double framePeriodS() const { return framePeriodS_; }
  float lastCommandedN() const { return lastCommandedN_; }
  int64_t framesEmitted() const { return framesEmitted_; }
  int64_t nonFiniteSamples() const { return nonFiniteSamples_; }

 private:
  template <class Sink>
  static void callSink(void* context, double frameTimeS, float forceN) {
    (*static_cast<Sink*>(context))(frameTimeS, forceN);
  }

  float sanitize(float forceN);
  // Adds the part [fromSample, toSample) (in samples from the block start) to the frame.
  void accumulate(const float* forceN, double fromSample, double toSample);
  // Emits the frame in progress if it holds any samples, and moves on to the next one.
  bool closeFrame(FrameSink sink, void* context);

  double framePeriodS_;
  double minForceN_;
  double maxForceN_;

  bool started_ = false;
  double nextBlockStartS_ = 0.0;
  int64_t frameIndex_ = 0;
  double weightedSum_ = 0.0;  // sum of force * (fraction of a sample inside the frame)
  double weight_ = 0.0;       // in samples
  float lastCommandedN_;
  int64_t framesEmitted_ = 0;
  int64_t nonFiniteSamples_ = 0;
};

}  // namespace kf
