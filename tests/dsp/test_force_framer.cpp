// ForceFramer: exact 1 ms means of the held signal at integer and non-integer samples per
// frame, NaN/Inf and clamping, the commanded output, and no drift over 10^7 frames; the
// anti-alias filter's frames against its design, exactly, and its response, step and edges.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "ForceFramer.hpp"

using kf::ForceFramer;
using kf::FrameFilter;
namespace frame_filter = kf::frame_filter;

namespace {

struct Frame {
  double timeS;
  float forceN;
};

struct Collect {
  std::vector<Frame>* frames;
  void operator()(double timeS, float forceN) { frames->push_back({timeS, forceN}); }
};

// Sample rate as a ratio of integers, so that references can be computed exactly:
// samples per 1 ms frame = num / den.
struct Rate {
  int64_t hz;
  int64_t num;  // samples per frame * den
  int64_t den;
};
const Rate kRates[] = {{44100, 441, 10}, {48000, 48, 1}, {96000, 96, 1}, {192000, 192, 1}};

// Runs `signal(sampleIndex)` through a framer in blocks of `blockSize`, block start times
// computed from the integer sample count (as the plugin does).
template <class Signal>
std::vector<Frame> runFramer(ForceFramer& framer, int64_t sampleRateHz, int64_t numSamples, int blockSize,
                             Signal signal, std::vector<float>* commanded = nullptr) {
  std::vector<Frame> frames;
  Collect sink{&frames};
  std::vector<float> block(blockSize), out(blockSize);
  const double durS = 1.0 / static_cast<double>(sampleRateHz);
  for (int64_t start = 0; start < numSamples; start += blockSize) {
    const int n = static_cast<int>(std::min<int64_t>(blockSize, numSamples - start));
    for (int i = 0; i < n; ++i) block[i] = signal(start + i);
    framer.process(static_cast<double>(start) / static_cast<double>(sampleRateHz), durS, block.data(), n, out.data(),
                   sink);
    if (commanded) commanded->insert(commanded->end(), out.begin(), out.begin() + n);
  }
  return frames;
}

// Exact mean over frame k of the held signal: frame k spans [k num, (k+1) num) and sample j
// spans [j den, (j+1) den), in units of 1/den sample.
template <class Signal>
double referenceMean(const Rate& rate, int64_t k, Signal signal) {
  const int64_t from = k * rate.num, to = (k + 1) * rate.num;
  double sum = 0.0;
  for (int64_t j = from / rate.den; j * rate.den < to; ++j) {
    const int64_t overlap = std::min(to, (j + 1) * rate.den) - std::max(from, j * rate.den);
    if (overlap > 0) sum += static_cast<double>(overlap) * signal(j);
  }
  return sum / static_cast<double>(rate.num);
}

constexpr double kPi = 3.14159265358979323846;

// A line fitted to the frames from `first` on: least squares of (force - 1 N) against sin and cos
// at f, each frame taken at its start plus `centreS` (what it stands for): {sin part, cos part},
// so that the gain is twice their length and the phase left is the cos part.
struct LineFit {
  double sinPart, cosPart;
};
LineFit fitLine(const std::vector<Frame>& frames, size_t first, double f, double centreS) {
  double ss = 0, sc = 0, cc = 0, ys = 0, yc = 0;
  for (size_t k = first; k < frames.size(); ++k) {
    const double t = frames[k].timeS + centreS;
    const double s = std::sin(2 * kPi * f * t), c = std::cos(2 * kPi * f * t), y = frames[k].forceN - 1.0;
    ss += s * s;
    sc += s * c;
    cc += c * c;
    ys += y * s;
    yc += y * c;
  }
  const double det = ss * cc - sc * sc;
  return {(ys * cc - yc * sc) / det, (yc * ss - ys * sc) / det};
}

}  // namespace

TEST_CASE("ForceFramer: a constant gives exactly that value in every frame", "[framer]") {
  for (const Rate& rate : kRates) {
    for (int blockSize : {1, 7, 64, 441, 1024}) {
      ForceFramer framer;
      const int64_t numSamples = 50 * rate.num / rate.den + 1;  // 50 frames
      auto frames = runFramer(framer, rate.hz, numSamples, blockSize, [](int64_t) { return 0.7f; });
      INFO("rate " << rate.hz << " block " << blockSize);
      REQUIRE(frames.size() == 50);
      for (size_t k = 0; k < frames.size(); ++k) {
        CHECK(frames[k].timeS == static_cast<double>(k) * 0.001);
        CHECK(frames[k].forceN == 0.7f);
      }
    }
  }
}

TEST_CASE("ForceFramer: 1 kHz square gives the exact mean of the held signal", "[framer]") {
  for (const Rate& rate : kRates) {
    // High while the sample starts in the first half of its millisecond.
    auto square = [&](int64_t j) { return (j * rate.den) % rate.num * 2 < rate.num ? 1.2f : 0.2f; };
    for (int blockSize : {1, 3, 64, 1024}) {
      ForceFramer framer;
      auto frames = runFramer(framer, rate.hz, 200 * rate.num / rate.den, blockSize, square);
      INFO("rate " << rate.hz << " block " << blockSize);
      REQUIRE(frames.size() == 200);
      double worst = 0.0;
      for (size_t k = 0; k < frames.size(); ++k)
        worst = std::max(worst, std::fabs(frames[k].forceN - referenceMean(rate, k, square)));
      CHECK(worst < 1e-6);
      if (rate.num % rate.den == 0) {
        // Whole samples per frame, half of them high: 0.7 N exactly.
        for (const Frame& f : frames) CHECK(f.forceN == Approx(0.7).margin(1e-6));
      }
    }
  }
}

TEST_CASE("ForceFramer: 44.1 kHz weights samples that straddle a boundary", "[framer]") {
  // Sample 44 spans [44, 45) samples; frame 0 ends at 44.1: 0.1 of it belongs to frame 0.
  ForceFramer framer(0.001, 0.0, 100.0);
  auto frames = runFramer(framer, 44100, 90, 90, [](int64_t j) { return j == 44 ? 10.0f : 0.0f; });
  REQUIRE(frames.size() == 2);
  CHECK(frames[0].forceN == Approx(10.0 * 0.1 / 44.1).epsilon(1e-6));
  CHECK(frames[1].forceN == Approx(10.0 * 0.9 / 44.1).epsilon(1e-6));
}

TEST_CASE("ForceFramer: NaN and Inf samples count as the minimum", "[framer]") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  ForceFramer framer(0.001, 0.14, 1.4);
  // Frame 0: all NaN. Frame 1: half +Inf, half 1.0. Frame 2: one -Inf among 1.0.
  auto signal = [&](int64_t j) -> float {
    if (j < 48) return nan;
    if (j < 96) return j < 72 ? inf : 1.0f;
    return j == 100 ? -inf : 1.0f;
  };
  auto frames = runFramer(framer, 48000, 144, 64, signal);
  REQUIRE(frames.size() == 3);
  CHECK(frames[0].forceN == 0.14f);
  CHECK(frames[1].forceN == Approx((24 * 0.14 + 24 * 1.0) / 48).epsilon(1e-6));
  CHECK(frames[2].forceN == Approx((0.14 + 47 * 1.0) / 48).epsilon(1e-6));
  CHECK(framer.nonFiniteSamples() == 48 + 24 + 1);
}

TEST_CASE("ForceFramer: each frame's mean is clamped to the device range", "[framer]") {
  ForceFramer framer(0.001, 0.14, 1.4);
  auto signal = [](int64_t j) -> float {
    if (j < 48) return 5.0f;
    if (j < 96) return -3.0f;
    if (j < 144) return 1e30f;
    return j % 2 ? 2.0f : 0.0f;  // mean 1.0: inside the range, though every sample is outside
  };
  auto frames = runFramer(framer, 48000, 192, 1024, signal);
  REQUIRE(frames.size() == 4);
  CHECK(frames[0].forceN == 1.4f);
  CHECK(frames[1].forceN == 0.14f);
  CHECK(frames[2].forceN == 1.4f);
  CHECK(frames[3].forceN == Approx(1.0).epsilon(1e-6));
}

TEST_CASE("ForceFramer: commanded output is the last completed frame, from its last sample", "[framer]") {
  for (int blockSize : {1, 10, 64, 1024}) {
    ForceFramer framer(0.001, 0.14, 1.4);
    std::vector<float> commanded;
    auto signal = [](int64_t j) { return j < 48 ? 1.0f : 0.5f; };
    runFramer(framer, 48000, 200, blockSize, signal, &commanded);
    INFO("block " << blockSize);
    REQUIRE(commanded.size() == 200);
    for (int i = 0; i < 47; ++i) CHECK(commanded[i] == 0.14f);  // nothing completed: magnet off
    for (int i = 47; i < 95; ++i) CHECK(commanded[i] == 1.0f);  // sample 47 completes frame 0
    for (int i = 95; i < 200; ++i) CHECK(commanded[i] == 0.5f);
  }
}

TEST_CASE("ForceFramer: block sizes 1..1024 give the same frames", "[framer]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.0f, 1.6f);
  std::vector<float> noise(44100 / 4);
  for (float& v : noise) v = uni(rng);
  auto signal = [&](int64_t j) { return noise[static_cast<size_t>(j)]; };
  const FrameFilter filter = GENERATE(FrameFilter::kMean, FrameFilter::kAntiAlias);
  ForceFramer reference(0.001, 0.14, 1.4, filter);
  auto expected = runFramer(reference, 44100, noise.size(), 1, signal);
  REQUIRE(expected.size() == 250);  // 11025 samples = 250 frames, the last ends on the last one
  for (int blockSize : {2, 5, 63, 64, 100, 512, 1023, 1024}) {
    ForceFramer framer(0.001, 0.14, 1.4, filter);
    auto frames = runFramer(framer, 44100, noise.size(), blockSize, signal);
    INFO("block " << blockSize);
    REQUIRE(frames.size() == expected.size());
    double worst = 0.0;
    for (size_t k = 0; k < frames.size(); ++k) {
      CHECK(frames[k].timeS == expected[k].timeS);
      worst = std::max(worst, static_cast<double>(std::fabs(frames[k].forceN - expected[k].forceN)));
    }
    CHECK(worst < 1e-6);
  }
  // Irregular block sizes, as a host with varying buffers would give.
  ForceFramer framer(0.001, 0.14, 1.4, filter);
  std::vector<Frame> frames;
  Collect sink{&frames};
  std::uniform_int_distribution<int> sizes(1, 1024);
  for (size_t start = 0; start < noise.size();) {
    const int n = static_cast<int>(std::min<size_t>(sizes(rng), noise.size() - start));
    framer.process(static_cast<double>(start) / 44100.0, 1.0 / 44100.0, noise.data() + start, n, nullptr, sink);
    start += n;
  }
  REQUIRE(frames.size() == expected.size());
  for (size_t k = 0; k < frames.size(); ++k) CHECK(frames[k].forceN == Approx(expected[k].forceN).margin(1e-6));
}

TEST_CASE("ForceFramer: no drift over 10^7 frames", "[framer][long]") {
  // 11.025 kHz: 11.025 samples per frame (non-integer), 1.1e8 samples, 10^4 s of audio time.
  const Rate rate{11025, 441, 40};
  // High while the sample starts in an even frame: every frame boundary cuts a sample.
  auto square = [&](int64_t j) { return (j * rate.den) % (2 * rate.num) < rate.num ? 1.0f : 0.25f; };
  const int64_t numFrames = 10000000;
  const int64_t numSamples = numFrames * rate.num / rate.den;
  REQUIRE(numSamples * rate.den == numFrames * rate.num);

  ForceFramer framer(0.001, 0.0, 2.0);
  struct Check {
    const Rate* rate;
    decltype(square)* signal;
    int64_t count = 0;
    int64_t wrongTimes = 0;
    double worstError = 0.0;
    void operator()(double timeS, float forceN) {
      if (timeS != static_cast<double>(count) * 0.001) ++wrongTimes;
      if (count % 97 == 0 || count > 9999000)  // a spread sample, and all of the last second
        worstError = std::max(worstError, std::fabs(forceN - referenceMean(*rate, count, *signal)));
      ++count;
    }
  } check{&rate, &square};
  std::vector<float> block(1024);
  for (int64_t start = 0; start < numSamples; start += 1024) {
    const int n = static_cast<int>(std::min<int64_t>(1024, numSamples - start));
    for (int i = 0; i < n; ++i) block[i] = square(start + i);
    framer.process(static_cast<double>(start) / 11025.0, 1.0 / 11025.0, block.data(), n, nullptr, check);
  }
  CHECK(check.count == numFrames);  // the last frame ends exactly on the last sample
  CHECK(check.wrongTimes == 0);
  CHECK(check.worstError < 1e-5);
}

TEST_CASE("ForceFramer: a jump in block time closes the frame in progress", "[framer]") {
  const FrameFilter filter = GENERATE(FrameFilter::kMean, FrameFilter::kAntiAlias);
  ForceFramer framer(0.001, 0.14, 1.4, filter);
  std::vector<Frame> frames;
  Collect sink{&frames};
  std::vector<float> ones(24, 1.0f);
  framer.process(0.0, 1.0 / 48000, ones.data(), 24, nullptr, sink);  // half of frame 0
  REQUIRE(frames.empty());
  // Jump to 10.5 ms: frame 0 is closed with its half, then the second half of frame 10.
  framer.process(0.0105, 1.0 / 48000, ones.data(), 24, nullptr, sink);
  REQUIRE(frames.size() == 2);
  CHECK(frames[0].timeS == 0.0);
  CHECK(frames[0].forceN == 1.0f);
  CHECK(frames[1].timeS == Approx(0.010));
  CHECK(frames[1].forceN == 1.0f);
}

TEST_CASE("ForceFramer: its frequency response at 1 and 8 kHz frames is the design's, a boxcar of the held samples",
          "[framer]") {
  // The design: a frame is the mean of its M held samples (M = sample rate x frame period), so a
  // sine of f in gives, at the frame rate, a sine of gain |sin(pi f M / fs) / (M sin(pi f / fs))|
  // delayed by (M - 1) / 2 samples from the frame's start (its centre). The framer's rate is
  // the device's force rate: 1 kHz (the paper's) or 8 kHz (a 2.1 board, PROTOCOL.md 3.1).
  for (const double frameHz : {1000.0, 8000.0}) {
    for (const int64_t fs : {int64_t{48000}, int64_t{96000}, int64_t{192000}}) {
      const double m = static_cast<double>(fs) / frameHz;
      for (const double fraction : {0.05, 0.2, 0.35, 0.45}) {
        const double f = fraction * frameHz;
        ForceFramer framer(1.0 / frameHz, 0.0, 2.0);
        const int64_t frames = 4000;
        auto sine = [&](int64_t j) { return static_cast<float>(1.0 + 0.5 * std::sin(2 * kPi * f * j / fs)); };
        const auto out = runFramer(framer, fs, static_cast<int64_t>(frames * m), 64, sine);
        REQUIRE(out.size() >= static_cast<size_t>(frames - 1));
        // The line at each frame's centre (its start plus (M - 1) / 2 samples).
        const auto [a, b] = fitLine(out, 0, f, (m - 1) / 2 / fs);
        const double design = std::fabs(std::sin(kPi * f * m / fs) / (m * std::sin(kPi * f / fs)));
        INFO("frames at " << frameHz << " Hz, fs " << fs << ", f " << f << " Hz: gain " << 2 * std::hypot(a, b)
                          << ", design " << design);
        // float frames (2^-24 of 1.5 N) over 4000 of them: far under 1e-5 of the 0.5 N sine.
        CHECK(2 * std::hypot(a, b) == Approx(design).margin(1e-5));
        CHECK(2 * b == Approx(0.0).margin(1e-5));  // no delay beyond the frame's centre
      }
    }
  }
}

namespace {

// The anti-alias filter's frame k from the exact means of the held signal over quarter frames,
// each clamped to the range (FrameFilter.hpp), the bins before the first taken as the first's.
template <class Signal>
double referenceFiltered(const Rate& rate, int64_t k, Signal signal, double minN, double maxN) {
  const Rate bins{rate.hz, rate.num, rate.den * frame_filter::kBinsPerFrame};
  double sum = 0.0;
  for (int j = 0; j < frame_filter::kTaps; ++j) {
    const int64_t bin =
        std::max<int64_t>(0, k * frame_filter::kBinsPerFrame + frame_filter::kBinsPerFrame - frame_filter::kTaps + j);
    sum += frame_filter::tap(j) * std::clamp(referenceMean(bins, bin, signal), minN, maxN);
  }
  return std::clamp(sum, minN, maxN);
}

}  // namespace

TEST_CASE("ForceFramer's anti-alias filter: the frames are the design's FIR over exact quarter-frame means",
          "[framer][antialias]") {
  // Every rate, 44.1 kHz's 11.025 samples per quarter frame included; a square that every bin
  // boundary cuts and noise. The taps themselves sum to 1 (a constant keeps its value).
  double tapSum = 0.0;
  for (int j = 0; j < frame_filter::kTaps; ++j) tapSum += frame_filter::tap(j);
  CHECK(tapSum == Approx(1.0).margin(1e-9));
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uni(0.0f, 1.6f);
  std::vector<float> noise(192 * 300);
  for (float& v : noise) v = uni(rng);
  for (const Rate& rate : kRates) {
    auto square = [&](int64_t j) { return (j * rate.den * 3) % rate.num * 2 < rate.num ? 1.2f : 0.2f; };
    auto random = [&](int64_t j) { return noise[static_cast<size_t>(j)]; };
    for (int blockSize : {1, 64, 1024}) {
      INFO("rate " << rate.hz << " block " << blockSize);
      ForceFramer onSquare(0.001, 0.14, 1.4, FrameFilter::kAntiAlias);
      ForceFramer onNoise(0.001, 0.14, 1.4, FrameFilter::kAntiAlias);
      const auto squareFrames = runFramer(onSquare, rate.hz, 200 * rate.num / rate.den, blockSize, square);
      const auto noiseFrames = runFramer(onNoise, rate.hz, 200 * rate.num / rate.den, blockSize, random);
      REQUIRE(squareFrames.size() == 200);
      REQUIRE(noiseFrames.size() == 200);
      double worst = 0.0;
      for (size_t k = 0; k < 200; ++k) {
        CHECK(squareFrames[k].timeS == static_cast<double>(k) * 0.001);
        worst = std::max(worst, std::fabs(squareFrames[k].forceN - referenceFiltered(rate, k, square, 0.14, 1.4)));
        worst = std::max(worst, std::fabs(noiseFrames[k].forceN - referenceFiltered(rate, k, random, 0.14, 1.4)));
      }
      CHECK(worst < 1e-6);
    }
  }
}

TEST_CASE("ForceFramer's anti-alias filter: its response at 1 and 8 kHz frames, aliases included, is the design's",
          "[framer][antialias]") {
  // Quarter frames of L whole samples: a sine of f in gives, at the frame rate, a sine of (signed)
  // gain  sum_j tap(j) cos(2 pi f (j - 7.5) L / fs) * sin(pi f L / fs) / (L sin(pi f / fs))  centred
  // 2 frames and half a sample before the frame's end (1.5 frames before the mean's centre). A line
  // above half the frame rate is seen at its alias, the same fit. Then the design's claims: with the
  // board's hold within one Weber fraction (0.11) up to 0.3 F, and -30 dB from 0.7 F up.
  const struct {
    double frameHz;
    int64_t fs;
  } cases[] = {{1000, 48000}, {1000, 96000}, {8000, 96000}, {8000, 192000}};
  for (const auto& c : cases) {
    const double m = static_cast<double>(c.fs) / c.frameHz, l = m / frame_filter::kBinsPerFrame;
    for (const double fraction : {0.05, 0.2, 0.3, 0.45, 0.7, 0.75, 0.9, 1.3}) {
      const double f = fraction * c.frameHz;
      ForceFramer framer(1.0 / c.frameHz, 0.0, 2.0, FrameFilter::kAntiAlias);
      auto sine = [&](int64_t j) { return static_cast<float>(1.0 + 0.5 * std::sin(2 * kPi * f * j / c.fs)); };
      const auto out = runFramer(framer, c.fs, static_cast<int64_t>(4000 * m), 64, sine);
      REQUIRE(out.size() == 4000);
      // After the filter's start (4 frames), at the frame's end less the group delay of 2 frames
      // and the held samples' half sample.
      const auto [a, b] = fitLine(out, 4, f, 1.0 / c.frameHz - 2.0 / c.frameHz - 0.5 / c.fs);
      double design = 0.0;
      for (int j = 0; j < frame_filter::kTaps; ++j)
        design += frame_filter::tap(j) * std::cos(2 * kPi * f * (j - 7.5) * l / c.fs);
      design *= std::sin(kPi * f * l / c.fs) / (l * std::sin(kPi * f / c.fs));
      INFO("frames at " << c.frameHz << " Hz, fs " << c.fs << ", f " << f << " Hz: gain " << 2 * a << " (phase left "
                        << 2 * b << "), design " << design);
      // float frames (2^-24 of 1.5 N) over 4000 of them: far under 1e-5 of the 0.5 N sine.
      CHECK(2 * a == Approx(design).margin(1e-5));
      CHECK(2 * b == Approx(0.0).margin(1e-5));
      const double held = std::fabs(2 * a) * std::sin(kPi * fraction) / (kPi * fraction);
      if (fraction <= 0.3) CHECK(std::fabs(held - 1.0) < 0.11);
      if (fraction >= 0.7) CHECK(std::fabs(2 * a) < std::pow(10.0, -30.0 / 20));
    }
  }
}

TEST_CASE("ForceFramer's anti-alias filter: a step rings by 10.3 % at most, settles in 4 frames, stays in range",
          "[framer][antialias]") {
  // The taps' running sums (the step response) reach -0.1029 and 1.1029: a step of height h is
  // undershot, then overshot, by at most 0.103 h, and the 4th frame after it is exact.
  const int64_t fs = 96000;  // 8 kHz frames of 12 samples, the step on a frame's start
  for (const float to : {1.0f, 1.4f}) {
    ForceFramer framer(1.0 / 8000, 0.14, 1.4, FrameFilter::kAntiAlias);
    const auto out = runFramer(framer, fs, 12 * 60, 64, [&](int64_t j) { return j < 12 * 20 ? 0.3f : to; });
    REQUIRE(out.size() == 60);
    const double ring = 0.1030 * (to - 0.3);
    for (size_t k = 0; k < out.size(); ++k) {
      INFO("frame " << k << ": " << out[k].forceN);
      CHECK(out[k].forceN >= 0.3 - ring);
      CHECK(out[k].forceN <= std::min(to + ring, 1.4));
      if (k < 20) CHECK(out[k].forceN == Approx(0.3).margin(1e-6));
      if (k >= 23) CHECK(out[k].forceN == Approx(to).margin(1e-6));
    }
    float most = 0.0f;
    for (const Frame& frame : out) most = std::max(most, frame.forceN);
    CHECK(most > (to < 1.4f ? to + 0.1 * (to - 0.3) : 1.39));  // it does ring, or meets the limit
  }
}

TEST_CASE("ForceFramer's anti-alias filter: NaN and Inf count as the minimum, silence stays at it, no denormals",
          "[framer][antialias]") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  ForceFramer framer(1.0 / 8000, 0.14, 1.4, FrameFilter::kAntiAlias);
  // 10 frames of NaN, 10 of +-Inf, 10 of denormals, 10 of 0: every frame at the minimum, exactly.
  auto signal = [&](int64_t j) -> float {
    if (j < 60) return nan;
    if (j < 120) return j % 2 ? inf : -inf;
    if (j < 180) return 1e-40f;
    return 0.0f;
  };
  const auto out = runFramer(framer, 48000, 240, 64, signal);
  REQUIRE(out.size() == 40);
  for (const Frame& frame : out) CHECK(frame.forceN == 0.14f);
  CHECK(framer.nonFiniteSamples() == 120);
}
