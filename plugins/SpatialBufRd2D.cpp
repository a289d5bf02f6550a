// SpatialBufRd2D: a 2D surface laid out on the table, read at the puck's (x, y).
// Inputs: bufnum (a mono buffer holding a matrix row after row), x, y (mm), width (samples per
// row), samplesPerMmX, samplesPerMmY, originX, originY (mm), interpolation (1, 2, 4). All but x
// and y are read once per block. Bad inputs keep the last good value, as SpatialBufRd's do
// (silence before a first good samplesPerMm, origin 0 before a first finite one), said once; a
// width that is no whole number of 1 .. frames silences the output.
#include <cmath>
#include <cstdio>

#include "AudioClock.hpp"
#include "BufferLookup.hpp"
#include "PluginShared.hpp"
#include "PostLimiter.hpp"
#include "SurfaceReader.hpp"

namespace {

enum Input { kBufnum, kX, kY, kWidth, kSamplesPerMmX, kSamplesPerMmY, kOriginX, kOriginY, kInterpolation };

// Why a block came out silent; posted once each time it changes.
enum class BufferProblem { None, BadBufnum, NotAllocated, NotMono, BadWidth };

enum BadInput { kBadSamplesPerMmX, kBadSamplesPerMmY, kBadOriginX, kBadOriginY };

class SpatialBufRd2D : public SCUnit {
 public:
  SpatialBufRd2D() { set_calc_function<SpatialBufRd2D, &SpatialBufRd2D::next>(); }

 private:
  void next(int numSamples) {
    kf::SurfaceLayout layout;
    layout.samplesPerMmX = usableSamplesPerMm(kSamplesPerMmX, kBadSamplesPerMmX, mGoodSamplesPerMmX, "samplesPerMmX");
    layout.samplesPerMmY = usableSamplesPerMm(kSamplesPerMmY, kBadSamplesPerMmY, mGoodSamplesPerMmY, "samplesPerMmY");
    layout.originXMm = usableOrigin(kOriginX, kBadOriginX, mGoodOriginXMm, "originX");
    layout.originYMm = usableOrigin(kOriginY, kBadOriginY, mGoodOriginYMm, "originY");
    const SndBuf* buf = mBuffer.find(mWorld, mParent, in0(kBufnum));
    if (mBuffer.isBad()) return silence(BufferProblem::BadBufnum, buf, numSamples);
    if (buf == nullptr) return silence(BufferProblem::NotAllocated, buf, numSamples);
    LOCK_SNDBUF_SHARED(buf);  // held for the block, as SpatialBufRd does (supernova)
    if (buf->data == nullptr || buf->frames <= 0) return silence(BufferProblem::NotAllocated, buf, numSamples);
    if (buf->channels != 1) return silence(BufferProblem::NotMono, buf, numSamples);
    // A whole number of samples per row, at most the buffer's frames; a last partial row is not read.
    const float width = in0(kWidth);
    if (!(width >= 1.f && width <= static_cast<float>(buf->frames)) || width != std::floor(width))
      return silence(BufferProblem::BadWidth, buf, numSamples);
    report(BufferProblem::None, buf);
    if (layout.samplesPerMmX == 0.0 || layout.samplesPerMmY == 0.0) return zero(numSamples);

    const auto columns = static_cast<int64_t>(width);
    const kf::SurfaceView surface{buf->data, columns, buf->frames / columns};
    const auto interpolation = kf::interpolationFromCode(kf::sc::codeOf(in0(kInterpolation)));
    kf::readSurfaceBlock(surface, in(kX), isAudioRateIn(kX) ? 1 : 0, in(kY), isAudioRateIn(kY) ? 1 : 0, layout,
                         interpolation, out(0), numSamples);
  }

  void silence(BufferProblem problem, const SndBuf* buf, int numSamples) {
    report(problem, buf);
    zero(numSamples);
  }

  void zero(int numSamples) { std::fill_n(out(0), numSamples, 0.f); }

  double usableSamplesPerMm(int input, BadInput kind, double& good, const char* name) {
    const float value = in0(input);
    if (value > 0.f && std::isfinite(value)) return good = value;
    if (mBadInputs.first(kind))
      kf::sc::postFromRt(mWorld,
                         "SpatialBufRd2D: %s %g is not a finite number > 0; the last good value is kept (silence "
                         "before the first).\n",
                         name, kf::sc::shownValue(value));
    return good;
  }

  double usableOrigin(int input, BadInput kind, double& good, const char* name) {
    const float value = in0(input);
    if (std::isfinite(value)) return good = value;
    if (mBadInputs.first(kind))
      kf::sc::postFromRt(mWorld,
                         "SpatialBufRd2D: %s %g is not finite; the last finite value is kept (0 before the first).\n",
                         name, kf::sc::shownValue(value));
    return good;
  }

  // Posts a buffer problem as BufferProblemPosts allows (once per change, a second apart a kind).
  void report(BufferProblem problem, const SndBuf* buf) {
    char more[64];
    if (!mPosts.shouldPost(mWorld, static_cast<int>(problem), more)) return;
    if (problem == BufferProblem::BadBufnum)
      kf::sc::postFromRt(mWorld, "SpatialBufRd2D: bufnum %g is not a buffer number 0..%d; output is silent.%s\n",
                         kf::sc::shownValue(mBuffer.input()),
                         static_cast<int>(mWorld->mNumSndBufs) + mParent->localBufNum - 1, more);
    else if (problem == BufferProblem::NotAllocated)
      kf::sc::postFromRt(mWorld, "SpatialBufRd2D: buffer %d is not allocated or empty; output is silent.%s\n",
                         mBuffer.bufnum(), more);
    else if (problem == BufferProblem::NotMono)
      kf::sc::postFromRt(mWorld,
                         "SpatialBufRd2D: buffer %d has %d channels; a surface is one channel, row after row. Output "
                         "is silent.%s\n",
                         mBuffer.bufnum(), buf->channels, more);
    else if (problem == BufferProblem::BadWidth)
      kf::sc::postFromRt(mWorld,
                         "SpatialBufRd2D: width %g is not a whole number of samples 1..%d (buffer %d's frames); output "
                         "is silent.%s\n",
                         kf::sc::shownValue(in0(kWidth)), buf->frames, mBuffer.bufnum(), more);
  }

  kf::sc::BufferLookup mBuffer;
  kf::sc::BufferProblemPosts<5> mPosts;
  kf::sc::FirstTimeOnly mBadInputs;
  double mGoodSamplesPerMmX = 0.0, mGoodSamplesPerMmY = 0.0;  // the last good values, 0 before the first
  double mGoodOriginXMm = 0.0, mGoodOriginYMm = 0.0;          // the last finite origins, 0 before the first
};

}  // namespace

void registerSpatialBufRd2D() { registerUnit<SpatialBufRd2D>(ft, "SpatialBufRd2D"); }
