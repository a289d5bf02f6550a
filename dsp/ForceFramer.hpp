// ForceFramer: audio-rate force (N) -> one force per frame (1 ms by default), the unit in which
// the paper's system programs friction ("durations down to 1 ms"): the frame's mean, or an
// anti-alias filter over the last four frames (FrameFilter.hpp says when and what it costs).
//
// Frames are aligned on audio time: frame k covers [k * P, (k + 1) * P), and is cut into bins
// (one for the mean, four quarter frames for the filter). Each sample is taken as constant over
// its own duration [t, t + sampleDur) and weighted by the part of that duration inside the bin,
// so a bin's value is the exact mean of the held signal even when a bin is not a whole number of
// samples (44.1 samples at 44.1 kHz). Boundaries are computed from the caller's block start
// time and k * P in double, never by accumulating P, so nothing drifts over long runs.
//
// NaN/Inf samples count as minForceN (magnet off is the safe value); each frame's value is
// clamped to [minForceN, maxForceN]. Nothing here allocates.
#pragma once

#include <cstdint>

#include "FrameFilter.hpp"
#include "PaperProfile.hpp"

namespace kf {

class ForceFramer {
 public:
  // Receives each completed frame: its start time (audio seconds) and clamped mean force.
  using FrameSink = void (*)(void* context, double frameTimeS, float forceN);

  ForceFramer(double framePeriodS = paper::device::forceFramePeriodS, double minForceN = paper::device::minForceN,
              double maxForceN = paper::device::maxForceN, FrameFilter filter = FrameFilter::kMean);

  void setForceRange(double minForceN, double maxForceN);
  // Forgets the frame in progress, the filter's past and the last commanded value (back to
  // minForceN).
  void reset();
  // Forgets the frame in progress (its samples are never sent) and the filter's past, keeping the
  // last commanded value and the count of frames; the next block opens the frame of its own first
  // sample, the filter starting as if the force had always been that sample's first bin's mean.
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
  FrameFilter filter() const { return filter_; }
  float lastCommandedN() const { return lastCommandedN_; }
  int64_t framesEmitted() const { return framesEmitted_; }
  int64_t nonFiniteSamples() const { return nonFiniteSamples_; }

 private:
  template <class Sink>
  static void callSink(void* context, double frameTimeS, float forceN) {
    (*static_cast<Sink*>(context))(frameTimeS, forceN);
  }

  // A non-finite sample is the minimum; `count` it in nonFiniteSamples (once per sample).
  float sanitize(float forceN, bool count = true);
  // Adds the part [fromSample, toSample) (in samples from the block start) to the bin.
  void accumulate(const float* forceN, double fromSample, double toSample);
  // Ends the bin in progress and moves on to the next one; at a frame's last bin, emits the frame
  // if any of its bins held samples. Returns whether it emitted.
  bool closeBin(FrameSink sink, void* context);
  // Ends the frame in progress with what it has (its missing bins hold the last bin's mean).
  bool closeFrame(FrameSink sink, void* context);
  // The frame's value from the bins' means: their mean's last, or the filter over the history.
  double frameValue() const;
  bool atFrameEnd() const;
  void forgetPast();

  double framePeriodS_;
  double minForceN_;
  double maxForceN_;
  FrameFilter filter_;
  int binsPerFrame_;

  bool started_ = false;
  double nextBlockStartS_ = 0.0;
  int64_t binIndex_ = 0;
  double weightedSum_ = 0.0;  // sum of force * (fraction of a sample inside the bin)
  double weight_ = 0.0;       // in samples
  bool frameHasSamples_ = false;
  double lastBinMeanN_ = 0.0;
  bool historySeeded_ = false;
  double history_[frame_filter::kTaps] = {};  // the last bins' means, a ring
  int historyNext_ = 0;                       // where the next bin's mean goes: the oldest
  float lastCommandedN_;
  int64_t framesEmitted_ = 0;
  int64_t nonFiniteSamples_ = 0;
};

}  // namespace kf
