// SlotForce: one force per device, however many FrictionOut write to it.
//
// The writers of a slot add their force of each block into one per-slot sum; the slot frames
// that sum once, so the device receives exactly one frame per millisecond. The rule, at every
// sample (forces in N, NaN/Inf as the minimum; weights clamped to [0, 1], NaN/Inf as 0):
//     combined = minForce + sum over writers of weight * max(0, force - minForce)
// then each 1 ms frame is the mean of `combined`, clamped to [minForce, maxForce] (ForceFramer),
// and the device applies its own limits (ForceSafety). So one writer commands its own force
// (a force below the minimum counts as the minimum), idle writers stay at the floor together
// (two do not double the magnet-off force), and forces above the floor add up. The weight is
// FrictionOut's fade (by default its synth's gate envelope): two versions crossfading with
// complementary weights (w and 1 - w, as JITLib's fades are) command a force between theirs,
// never more than the larger one.
//
// Writers register with the slot (constructor, destructor: FrictionOut), so the last writer of
// a block knows it is the last and frames the block at once: no added latency. (A writer that
// starts after the others of its first block have framed it joins from the next block.) A registered
// writer that does not run (a paused synth) leaves the block open; the first writer of the
// next block frames it then, one block late. Audio thread only; nothing allocates.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "ForceFramer.hpp"
#include "SlotTrajectory.hpp"  // BlockClock
#include "core/spec/DeviceSpec.hpp"

namespace kf::sc {

class SlotForce {
 public:
  static constexpr int kMaxBlockSamples = 4096;  // larger server blocks: the rest is the minimum

  // A new device (or none): its force range; the block in progress is dropped. Registrations
  // stay: they belong to the writers, not to the device.
  void reset(const DeviceSpec& spec);

  void registerWriter() { ++registered_; }
  void unregisterWriter() { registered_ = std::max(0, registered_ - 1); }
  int registeredWriters() const { return registered_; }

  // A writer's force for block `clock`: `forceN` has `numSamples` values, one per sample of the
  // block (audio rate) or a single value held over it (numSamples 1: control rate); so has its
  // weight `fade` (`fadeSamples` values), which scales the force above the minimum. `sink`
  // (double frameTimeS, float forceN, double frameEndS) -> float receives the frames of blocks
  // that complete here and returns the force the device actually commanded for it (after its
  // safety path), which the commanded output shows from then on. Returns true when this block has been framed (this
  // writer was the last).
  template <class Sink>
  bool write(const BlockClock& clock, const float* forceN, int numSamples, const float* fade, int fadeSamples,
             Sink& sink);
  // A writer of weight 1.
  template <class Sink>
  bool write(const BlockClock& clock, const float* forceN, int numSamples, Sink& sink) {
    const float one = 1.0f;
    return write(clock, forceN, numSamples, &one, 1, sink);
  }

  // A writer's weight as the rule takes it: clamped to [0, 1], NaN and Inf as 0 (the safe value).
  static double weightOf(float fade) { return std::isfinite(fade) ? std::clamp(fade, 0.0f, 1.0f) : 0.0; }

  // A writer went away (destructor, after unregisterWriter) during `clock`'s block: if it was
  // the last one missing, the block is framed now. If no writer is left, the frame in progress
  // (the part of a millisecond written before the block ended) is dropped: no writer can finish
  // it, and the device goes off (Device::requestOff drops the frames not yet sent). Closed later
  // by the next writer's first block, it would reach the device with a time long past, and a
  // frame that late raises the device's release latency (up to 0.1 s) for the writers after.
  template <class Sink>
  void writerGone(const BlockClock& clock, Sink& sink);

  // The commanded force (N) per sample of the last framed block, and the latest value.
  const float* commanded() const { return commanded_; }
  int64_t framedBlock() const { return framedBlock_; }
  float lastCommandedN() const { return framer_.lastCommandedN(); }
  int64_t framesEmitted() const { return framer_.framesEmitted(); }
  // The combined force (N, per sample, before any limit) of `block` if it was framed and is one
  // of the last two framed, else null; `numSamples` its length. FrictionDrive drives block b-1's
  // in block b, whichever side of the writers it runs (ARCHITECTURE.md, the audio drive).
  const float* combinedOf(int64_t block, int& numSamples) const {
    const int slot = static_cast<int>(block & 1);
    numSamples = combinedSamples_[slot];
    return block >= 0 && combinedBlock_[slot] == block ? combined_[slot] : nullptr;
  }

 private:
  template <class Sink>
  void frame(Sink& sink);
  void begin(const BlockClock& clock);

  double minForceN_ = 0.14;
  ForceFramer framer_;
  int registered_ = 0;
  int arrived_ = 0;
  bool open_ = false;  // a block has arrivals that are not framed yet
  BlockClock block_;
  int64_t framedBlock_ = -1;
  double excessN_[kMaxBlockSamples] = {};     // sum over writers of max(0, force - minimum); double,
                                              // so that one writer's force comes back exactly
  float combined_[2][kMaxBlockSamples] = {};  // by block parity: this block's and the previous
  int64_t combinedBlock_[2] = {-1, -1};
  int combinedSamples_[2] = {};
  float commanded_[kMaxBlockSamples] = {};
};

template <class Sink>
bool SlotForce::write(const BlockClock& clock, const float* forceN, int numSamples, const float* fade, int fadeSamples,
                      Sink& sink) {
  // A writer whose synth starts this block registers in its first calc (scsynth constructs
  // units then): if the writers before it have framed the block already, its force joins from
  // the next block, so no millisecond is framed twice.
  if (!open_ && framedBlock_ == clock.block) return false;
  if (!open_ || block_.block != clock.block) {
    if (open_) frame(sink);  // a writer of that block never came (paused): framed late
    begin(clock);
  }
  const int n = std::min(block_.numSamples, kMaxBlockSamples);
  for (int i = 0; i < n; ++i) {
    const float f = forceN[numSamples == 1 ? 0 : std::min(i, numSamples - 1)];
    // NaN and Inf are the minimum (magnet off, the safe value): they add nothing.
    if (std::isfinite(f) && f > minForceN_)
      excessN_[i] += weightOf(fade[fadeSamples == 1 ? 0 : std::min(i, fadeSamples - 1)]) * (f - minForceN_);
  }
  ++arrived_;
  if (arrived_ >= registered_) {
    frame(sink);
    return true;
  }
  return false;
}

template <class Sink>
void SlotForce::writerGone(const BlockClock& clock, Sink& sink) {
  if (open_ && block_.block == clock.block && arrived_ > 0 && arrived_ >= registered_) frame(sink);
  if (registered_ == 0) framer_.dropFrameInProgress();
}

template <class Sink>
void SlotForce::frame(Sink& sink) {
  const int n = std::min(block_.numSamples, kMaxBlockSamples);
  const int slot = static_cast<int>(block_.block & 1);
  float* combined = combined_[slot];
  for (int i = 0; i < n; ++i) combined[i] = static_cast<float>(minForceN_ + excessN_[i]);
  combinedBlock_[slot] = block_.block;
  combinedSamples_[slot] = n;
  const double periodS = framer_.framePeriodS();
  auto emit = [this, &sink, periodS](double frameTimeS, float forceN) {
    framer_.showCommanded(sink(frameTimeS, forceN, frameTimeS + periodS));
  };
  framer_.process(block_.startS, block_.sampleDurS, combined, n, commanded_, emit);
  open_ = false;
  framedBlock_ = block_.block;
}

}  // namespace kf::sc
