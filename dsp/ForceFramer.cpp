#include "ForceFramer.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace kf {

namespace {

// A boundary closer than this (in samples) to a sample edge is on it: the rounding of
// k * P and of the block start (1e-12 s at 10^4 s) must not leave slivers of a sample.
constexpr double kSnapSamples = 1e-6;

double snapToEdge(double positionSamples) {
  const double rounded = std::round(positionSamples);
  return std::fabs(positionSamples - rounded) < kSnapSamples ? rounded : positionSamples;
}

}  // namespace

ForceFramer::ForceFramer(double framePeriodS, double minForceN, double maxForceN, FrameFilter filter)
    : framePeriodS_(framePeriodS > 0.0 ? framePeriodS : 0.001),
      minForceN_(minForceN),
      maxForceN_(std::max(minForceN, maxForceN)),
      filter_(filter),
      binsPerFrame_(filter == FrameFilter::kAntiAlias ? frame_filter::kBinsPerFrame : 1),
      lastCommandedN_(static_cast<float>(minForceN)) {}

void ForceFramer::setForceRange(double minForceN, double maxForceN) {
  minForceN_ = minForceN;
  maxForceN_ = std::max(minForceN, maxForceN);
}

void ForceFramer::forgetPast() {
  started_ = false;
  weightedSum_ = 0.0;
  weight_ = 0.0;
  frameHasSamples_ = false;
  historySeeded_ = false;
}

void ForceFramer::reset() {
  forgetPast();
  lastCommandedN_ = static_cast<float>(minForceN_);
}

void ForceFramer::dropFrameInProgress() { forgetPast(); }

float ForceFramer::sanitize(float forceN, bool count) {
  if (std::isfinite(forceN)) return forceN;
  if (count) ++nonFiniteSamples_;
  return static_cast<float>(minForceN_);
}

void ForceFramer::accumulate(const float* forceN, double fromSample, double toSample) {
  double pos = fromSample;
  while (pos < toSample) {
    const int i = static_cast<int>(pos);
    if (pos == i && i + 1.0 <= toSample) {
      // A run of whole samples: plain sum, so a constant frame averages back exactly.
      const int end = static_cast<int>(toSample);
      double sum = 0.0;
      for (int k = i; k < end; ++k) sum += sanitize(forceN[k]);
      weightedSum_ += sum;
      weight_ += end - i;
      pos = end;
    } else {
      const double segEnd = std::min(i + 1.0, toSample);
      const double w = segEnd - pos;
      weightedSum_ += w * sanitize(forceN[i], pos == i);  // a sample cut by a boundary counts once
      weight_ += w;
      pos = segEnd;
    }
  }
}

bool ForceFramer::atFrameEnd() const {
  const int64_t bin = binIndex_ % binsPerFrame_;
  return bin == binsPerFrame_ - 1 || bin == -1;  // -1: a negative time's last bin
}

double ForceFramer::frameValue() const {
  if (filter_ == FrameFilter::kMean) return lastBinMeanN_;
  double sum = 0.0;
  for (int k = 0; k < frame_filter::kTaps; ++k)
    sum += frame_filter::tap(k) * history_[(historyNext_ + k) % frame_filter::kTaps];
  return sum;
}

bool ForceFramer::closeBin(FrameSink sink, void* context) {
  if (weight_ > 0.0) {
    // In range before the filter too: a request below the minimum (silence, 0 N) is the minimum,
    // not a step for the filter to ring above it.
    lastBinMeanN_ = std::clamp(weightedSum_ / weight_, minForceN_, maxForceN_);
    frameHasSamples_ = true;
    if (!historySeeded_ && filter_ == FrameFilter::kAntiAlias)
      std::fill(std::begin(history_), std::end(history_), lastBinMeanN_);
    historySeeded_ = filter_ == FrameFilter::kAntiAlias;  // the mean keeps no past
  }
  if (historySeeded_) {
    history_[historyNext_] = lastBinMeanN_;  // a bin without samples holds the last mean
    historyNext_ = (historyNext_ + 1) % frame_filter::kTaps;
  }
  weightedSum_ = 0.0;
  weight_ = 0.0;
  const bool frameEnds = atFrameEnd();
  const bool emit = frameEnds && frameHasSamples_;
  if (emit) {
    lastCommandedN_ = static_cast<float>(std::clamp(frameValue(), minForceN_, maxForceN_));
    ++framesEmitted_;
    const int64_t frame = (binIndex_ - (binsPerFrame_ - 1)) / binsPerFrame_;
    if (sink) sink(context, static_cast<double>(frame) * framePeriodS_, lastCommandedN_);
  }
  if (frameEnds) frameHasSamples_ = false;
  ++binIndex_;
  return emit;
}

bool ForceFramer::closeFrame(FrameSink sink, void* context) {
  bool emitted = false;
  bool frameEnds = false;
  do {
    frameEnds = atFrameEnd();
    emitted = closeBin(sink, context) || emitted;
  } while (!frameEnds);
  return emitted;
}

int ForceFramer::process(double blockStartTimeS, double sampleDurS, const float* forceN, int numSamples,
                         float* commandedN, FrameSink sink, void* context) {
  if (numSamples <= 0 || !(sampleDurS > 0.0)) return 0;
  int frames = 0;
  if (started_ && std::fabs(blockStartTimeS - nextBlockStartS_) > 0.5 * sampleDurS) {
    // Time jumped: what we have of the frame in progress is all it will get, and the filter
    // starts afresh from the new time's force.
    if (closeFrame(sink, context)) ++frames;
    forgetPast();
  }
  if (!started_) {
    // The bin holding the block's first sample (a start on a boundary opens the next one).
    binIndex_ =
        static_cast<int64_t>(std::floor((blockStartTimeS + kSnapSamples * sampleDurS) * binsPerFrame_ / framePeriodS_));
    weightedSum_ = 0.0;
    weight_ = 0.0;
    frameHasSamples_ = false;
    started_ = true;
  }
  nextBlockStartS_ = blockStartTimeS + numSamples * sampleDurS;

  int filled = 0;  // commandedN[0, filled) are written
  double pos = 0.0;
  const double n = numSamples;
  while (pos < n) {
    // Boundary from k * P, not from a running sum, so it cannot drift (the division by the bins
    // per frame, 1 or 4, is exact: a frame's last bin ends where the frame does).
    const double binEndS = static_cast<double>(binIndex_ + 1) * framePeriodS_ / binsPerFrame_;
    const double boundary = std::max(pos, snapToEdge((binEndS - blockStartTimeS) / sampleDurS));
    const double end = std::min(boundary, n);
    accumulate(forceN, pos, end);
    pos = end;
    if (boundary <= n) {
      // The sample that reaches the boundary completes the bin: it already shows a frame's value.
      const int completing = std::max(0, static_cast<int>(std::ceil(boundary)) - 1);
      const float before = lastCommandedN_;
      if (closeBin(sink, context)) ++frames;
      const float now = lastCommandedN_;
      if (commandedN) {
        for (; filled < completing; ++filled) commandedN[filled] = before;
        if (filled == completing)
          commandedN[filled++] = now;
        else
          commandedN[completing] = now;  // several frames in one sample: the newest wins
      }
    }
  }
  if (commandedN)
    for (; filled < numSamples; ++filled) commandedN[filled] = lastCommandedN_;
  return frames;
}

}  // namespace kf
