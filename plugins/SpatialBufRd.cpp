// SpatialBufRd: plays a buffer laid out on the surface, read at the puck's position.
// Inputs: bufnum, position (mm), samplesPerMm, origin (mm), interpolation (1, 2, 4), keep
// (0/1, optional). samplesPerMm, origin, interpolation and keep are read once per block.
// A bad samplesPerMm (NaN, inf, 0, negative) or origin (NaN, inf) keeps the last good value
// (silence before a first good samplesPerMm, origin 0 before a first finite one), said once.
// keep 1: when samplesPerMm or origin change, the sample under the puck stays in place (zoom
// about the puck): the layout is moved, in double, so that the index at the block's first
// position is the one the old mapping gave there. The read index stays continuous.
#include <cmath>
#include <cstdio>

#include "AudioClock.hpp"
#include "BufferLookup.hpp"
#include "PluginShared.hpp"
#include "PostLimiter.hpp"
#include "SpatialReader.hpp"

namespace {

enum Input { kBufnum, kPositionMm, kSamplesPerMm, kOriginMm, kInterpolation, kKeep };

// Why a block came out silent; posted once each time it changes.
enum class BufferProblem { None, BadBufnum, NotAllocated, ChannelMismatch };

// The kinds of bad layout input, each posted once per unit (FirstTimeOnly).
enum BadInput { kBadSamplesPerMm, kBadOrigin };

class SpatialBufRd : public SCUnit {
 public:
  // set_calc_function computes the first sample (next(1)), as SC's own UGens do.
  SpatialBufRd() { set_calc_function<SpatialBufRd, &SpatialBufRd::next>(); }

 private:
  void next(int numSamples) {
    // Before the buffer checks, so that the last good values are followed whatever the buffer.
    const double samplesPerMm = usableSamplesPerMm();
    const double inputOriginMm = usableOriginMm();
    const SndBuf* buf = mBuffer.find(mWorld, mParent, in0(kBufnum));
    if (mBuffer.isBad()) return silence(BufferProblem::BadBufnum, buf, numSamples);
    if (buf == nullptr) return silence(BufferProblem::NotAllocated, buf, numSamples);
    // Held for the block, as GET_BUF_SHARED does: under supernova another thread may reallocate
    // the buffer meanwhile (no-op in scsynth).
    LOCK_SNDBUF_SHARED(buf);
    if (buf->data == nullptr || buf->frames <= 0) return silence(BufferProblem::NotAllocated, buf, numSamples);
    if (buf->channels != static_cast<int>(mNumOutputs)) return silence(BufferProblem::ChannelMismatch, buf, numSamples);
    report(BufferProblem::None, buf);
    if (samplesPerMm == 0.0) return zeroOutputs(numSamples);  // no good samplesPerMm yet

    const kf::SignalView signal{buf->data, buf->frames, buf->channels};
    const double originMm = layoutOriginMm(samplesPerMm, inputOriginMm);
    const auto interpolation = kf::interpolationFromCode(kf::sc::codeOf(in0(kInterpolation)));
    // One call per block: indices for the whole block first, then the taps (see
    // readSpatialBlock), so an output buffer may share memory with the position input.
    kf::readSpatialBlock(signal, in(kPositionMm), isAudioRateIn(kPositionMm) ? 1 : 0, originMm, samplesPerMm,
                         interpolation, mOutBuf, numSamples);
  }

  void silence(BufferProblem problem, const SndBuf* buf, int numSamples) {
    report(problem, buf);
    zeroOutputs(numSamples);
  }

  void zeroOutputs(int numSamples) {
    for (uint32 c = 0; c < mNumOutputs; ++c) std::fill_n(out(c), numSamples, 0.f);
  }

  // samplesPerMm must be finite and > 0: 0 would hold one sample everywhere and a negative value
  // mirror the layout, neither what a user means. A bad value keeps the last good one, so that a
  // glitch in a modulated zoom does not jump; 0 (silence) while there has been none.
  double usableSamplesPerMm() {
    const float value = in0(kSamplesPerMm);
    if (value > 0.f && std::isfinite(value)) return mGoodSamplesPerMm = value;
    if (mBadInputs.first(kBadSamplesPerMm))
      kf::sc::postFromRt(mWorld,
                         "SpatialBufRd: samplesPerMm %g is not a finite number > 0; the last good value is kept "
                         "(silence before the first).\n",
                         kf::sc::shownValue(value));
    return mGoodSamplesPerMm;
  }

  // A NaN or infinite origin would make every index NaN: the last finite origin is kept, 0
  // while there has been none (the argument's default).
  double usableOriginMm() {
    const float value = in0(kOriginMm);
    if (std::isfinite(value)) return mGoodOriginMm = value;
    if (mBadInputs.first(kBadOrigin))
      kf::sc::postFromRt(mWorld,
                         "SpatialBufRd: origin %g is not finite; the last finite origin is kept (0 before the "
                         "first).\n",
                         kf::sc::shownValue(value));
    return mGoodOriginMm;
  }

  // The origin the block reads with: the input, or with keep on, one moved at every change of
  // samplesPerMm or origin so that the puck's sample stays where it is. Decided here, at the
  // block the change takes effect. Both values are good ones (finite, samplesPerMm > 0).
  double layoutOriginMm(double samplesPerMm, double originMm) {
    const bool keep = mNumInputs > kKeep && in0(kKeep) > 0.f;
    const bool changed = samplesPerMm != mLastSamplesPerMm || originMm != mLastOriginMm;
    if (!keep || !mStarted) {
      mLayoutOriginMm = originMm;
    } else if (changed) {
      const double positionMm = in(kPositionMm)[0];
      if (std::isfinite(positionMm))
        mLayoutOriginMm = positionMm - (positionMm - mLayoutOriginMm) * mLastSamplesPerMm / samplesPerMm;
    }
    mLastSamplesPerMm = samplesPerMm;
    mLastOriginMm = originMm;
    mStarted = true;
    return mLayoutOriginMm;
  }

  // Posts a buffer problem as BufferProblemPosts allows (once per change, a second apart a kind).
  void report(BufferProblem problem, const SndBuf* buf) {
    char more[64];
    if (!mPosts.shouldPost(mWorld, static_cast<int>(problem), more)) return;
    if (problem == BufferProblem::BadBufnum)
      kf::sc::postFromRt(mWorld, "SpatialBufRd: bufnum %g is not a buffer number 0..%d; output is silent.%s\n",
                         kf::sc::shownValue(mBuffer.input()),
                         static_cast<int>(mWorld->mNumSndBufs) + mParent->localBufNum - 1, more);
    else if (problem == BufferProblem::NotAllocated)
      kf::sc::postFromRt(mWorld, "SpatialBufRd: buffer %d is not allocated or empty; output is silent.%s\n",
                         mBuffer.bufnum(), more);
    else if (problem == BufferProblem::ChannelMismatch)
      kf::sc::postFromRt(mWorld, "SpatialBufRd: buffer %d has %d channels but numChannels is %d; output is silent.%s\n",
                         mBuffer.bufnum(), buf->channels, static_cast<int>(mNumOutputs), more);
  }

  kf::sc::BufferLookup mBuffer;
  kf::sc::BufferProblemPosts<4> mPosts;
  kf::sc::FirstTimeOnly mBadInputs;
  double mGoodSamplesPerMm = 0.0;  // the last good samplesPerMm, 0 before the first
  double mGoodOriginMm = 0.0;      // the last finite origin, 0 before the first
  bool mStarted = false;
  double mLastSamplesPerMm = 0.0;
  double mLastOriginMm = 0.0;
  double mLayoutOriginMm = 0.0;
};

}  // namespace

void registerSpatialBufRd() { registerUnit<SpatialBufRd>(ft, "SpatialBufRd"); }
