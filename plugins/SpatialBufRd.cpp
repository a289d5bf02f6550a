// SpatialBufRd: plays a buffer laid out on the surface, read at the puck's position.
// Inputs: bufnum, position (mm), samplesPerMm, origin (mm), interpolation (1, 2, 4), keep
// (0/1, optional). samplesPerMm, origin, interpolation and keep are read once per block.
// keep 1: when samplesPerMm or origin change, the sample under the puck stays in place (zoom
// about the puck): the layout is moved, in double, so that the index at the block's first
// position is the one the old mapping gave there. The read index stays continuous.
#include <cmath>

#include "PluginShared.hpp"
#include "SpatialReader.hpp"

namespace {

enum Input { kBufnum, kPositionMm, kSamplesPerMm, kOriginMm, kInterpolation, kKeep };

// Why a block came out silent; posted once each time it changes.
enum class BufferProblem { None, NotAllocated, ChannelMismatch };

class SpatialBufRd : public SCUnit {
 public:
  SpatialBufRd() {
    set_calc_function<SpatialBufRd, &SpatialBufRd::next>();
    next(1);
  }

 private:
  void next(int numSamples) {
    const SndBuf* buf = lookupBuffer();
    const int numChannels = static_cast<int>(mNumOutputs);
    BufferProblem problem = BufferProblem::None;
    if (buf == nullptr || buf->data == nullptr || buf->frames <= 0)
      problem = BufferProblem::NotAllocated;
    else if (buf->channels != numChannels)
      problem = BufferProblem::ChannelMismatch;
    report(problem, buf);
    if (problem != BufferProblem::None) {
      for (int c = 0; c < numChannels; ++c) std::fill_n(out(c), numSamples, 0.f);
      return;
    }

    const kf::SignalView signal{buf->data, buf->frames, buf->channels};
    const double samplesPerMm = in0(kSamplesPerMm);
    const double originMm = layoutOriginMm(samplesPerMm, in0(kOriginMm));
    const auto interpolation = kf::interpolationFromCode(static_cast<int>(in0(kInterpolation)));
    // One call per block: indices for the whole block first, then the taps (see
    // readSpatialBlock), so an output buffer may share memory with the position input.
    kf::readSpatialBlock(signal, in(kPositionMm), isAudioRateIn(kPositionMm) ? 1 : 0, originMm, samplesPerMm,
                         interpolation, mOutBuf, numSamples);
  }

  // The origin the block reads with: the input, or with keep on, one moved at every change of
  // samplesPerMm or origin so that the puck's sample stays where it is. Decided here, at the
  // block the change takes effect.
  double layoutOriginMm(double samplesPerMm, double originMm) {
    const bool keep = mNumInputs > kKeep && in0(kKeep) > 0.f;
    const bool changed = samplesPerMm != mLastSamplesPerMm || originMm != mLastOriginMm;
    if (!keep || !mStarted) {
      mLayoutOriginMm = originMm;
    } else if (changed && std::isfinite(samplesPerMm) && samplesPerMm != 0.0 && std::isfinite(mLastSamplesPerMm)) {
      const double positionMm = in(kPositionMm)[0];
      if (std::isfinite(positionMm))
        mLayoutOriginMm = positionMm - (positionMm - mLayoutOriginMm) * mLastSamplesPerMm / samplesPerMm;
    }
    mLastSamplesPerMm = samplesPerMm;
    mLastOriginMm = originMm;
    mStarted = true;
    return mLayoutOriginMm;
  }

  // The buffer for the bufnum input, global or local to the synth, or nullptr; looked up every
  // block so that a freed or swapped buffer is seen at once.
  const SndBuf* lookupBuffer() {
    const float fbufnum = in0(kBufnum);
    if (!(fbufnum >= 0.f)) return nullptr;
    const auto bufnum = static_cast<uint32>(fbufnum);
    mBufnum = static_cast<int>(bufnum);
    if (bufnum < mWorld->mNumSndBufs) return mWorld->mSndBufs + bufnum;
    const int localBufnum = static_cast<int>(bufnum - mWorld->mNumSndBufs);
    if (localBufnum < mParent->localBufNum) return mParent->mLocalSndBufs + localBufnum;
    return nullptr;
  }

  void report(BufferProblem problem, const SndBuf* buf) {
    if (problem == mProblem) return;
    mProblem = problem;
    if (problem == BufferProblem::NotAllocated)
      kf::sc::postFromRt(mWorld, "SpatialBufRd: buffer %d is not allocated or empty; output is silent.\n", mBufnum);
    else if (problem == BufferProblem::ChannelMismatch)
      kf::sc::postFromRt(mWorld, "SpatialBufRd: buffer %d has %d channels but numChannels is %d; output is silent.\n",
                         mBufnum, buf->channels, static_cast<int>(mNumOutputs));
  }

  BufferProblem mProblem = BufferProblem::None;
  int mBufnum = -1;
  bool mStarted = false;
  double mLastSamplesPerMm = 0.0;
  double mLastOriginMm = 0.0;
  double mLayoutOriginMm = 0.0;
};

}  // namespace

void registerSpatialBufRd() { registerUnit<SpatialBufRd>(ft, "SpatialBufRd"); }
