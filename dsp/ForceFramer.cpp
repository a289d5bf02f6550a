#include "ForceFramer.hpp"

#include <algorithm>
#include <cmath>

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

ForceFramer::ForceFramer(double framePeriodS, double minForceN, double maxForceN)
    : framePeriodS_(framePeriodS > 0.0 ? framePeriodS : 0.001),
      minForceN_(minForceN),
      maxForceN_(std::max(minForceN, maxForceN)),
      lastCommandedN_(static_cast<float>(minForceN)) {}

void ForceFramer::setForceRange(double minForceN, double maxForceN) {
  minForceN_ = minForceN;
  maxForceN_ = std::max(minForceN, maxForceN);
}

void ForceFramer::reset() {
  started_ = false;
  weightedSum_ = 0.0;
  weight_ = 0.0;
  lastCommandedN_ = static_cast<float>(minForceN_);
}

void ForceFramer::dropFrameInProgress() {
  started_ = false;
  weightedSum_ = 0.0;
  weight_ = 0.0;
}

float ForceFramer::sanitize(float forceN) {
  if (std::isfinite(forceN)) return forceN;
  ++nonFiniteSamples_;
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
      weightedSum_ += w * sanitize(forceN[i]);
      weight_ += w;
      pos = segEnd;
    }
  }
}

bool ForceFramer::closeFrame(FrameSink sink, void* context) {
  const bool emit = weight_ > 0.0;
  if (emit) {
    const double meanN = std::clamp(weightedSum_ / weight_, minForceN_, maxForceN_);
    lastCommandedN_ = static_cast<float>(meanN);
    ++framesEmitted_;
    if (sink) sink(context, static_cast<double>(frameIndex_) * framePeriodS_, lastCommandedN_);
  }
  weightedSum_ = 0.0;
  weight_ = 0.0;
  ++frameIndex_;
  return emit;
}

int ForceFramer::process(double blockStartTimeS, double sampleDurS, const float* forceN, int numSamples,
                         float* commandedN, FrameSink sink, void* context) {
  if (numSamples <= 0 || !(sampleDurS > 0.0)) return 0;
  int frames = 0;
  if (started_ && std::fabs(blockStartTimeS - nextBlockStartS_) > 0.5 * sampleDurS) {
    // Time jumped: what we have of the frame in progress is all it will get.
    if (closeFrame(sink, context)) ++frames;
    started_ = false;
  }
  if (!started_) {
    // The frame holding the block's first sample (a start on a boundary opens the next one).
    frameIndex_ = static_cast<int64_t>(std::floor((blockStartTimeS + kSnapSamples * sampleDurS) / framePeriodS_));
    weightedSum_ = 0.0;
    weight_ = 0.0;
    started_ = true;
  }
  nextBlockStartS_ = blockStartTimeS + numSamples * sampleDurS;

  int filled = 0;  // commandedN[0, filled) are written
  double pos = 0.0;
  const double n = numSamples;
  while (pos < n) {
    // Boundary from k * P, not from a running sum, so it cannot drift.
    const double frameEndS = static_cast<double>(frameIndex_ + 1) * framePeriodS_;
    const double boundary = std::max(pos, snapToEdge((frameEndS - blockStartTimeS) / sampleDurS));
    const double end = std::min(boundary, n);
    accumulate(forceN, pos, end);
    pos = end;
    if (boundary <= n) {
      // The sample that reaches the boundary completes the frame: it already shows the value.
      const int completing = std::max(0, static_cast<int>(std::ceil(boundary)) - 1);
      const float before = lastCommandedN_;
      if (closeFrame(sink, context)) ++frames;
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
