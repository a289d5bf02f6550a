// SlotForce: however many writers a slot has, the device gets one frame per millisecond, by
// the documented rule (forces above the minimum add up, each weighted by its writer's fade),
// without added latency.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "SlotForce.hpp"

using kf::sc::BlockClock;
using kf::sc::SlotForce;

namespace {

struct Frame {
  double timeS;
  float forceN;
  int64_t emittedInBlock;
};

struct Recorder {
  std::vector<Frame> frames;
  int64_t currentBlock = 0;
  float operator()(double timeS, float forceN, double /*endS*/) {
    frames.push_back({timeS, forceN, currentBlock});
    return forceN;  // a device that commands what it is asked
  }
};

BlockClock clockOf(int64_t block, int numSamples = 64, double sampleRate = 48000.0) {
  return BlockClock{block, block * numSamples / sampleRate, 1.0 / sampleRate, numSamples};
}

// A new SlotForce on the heap (it holds block-sized buffers).
std::unique_ptr<SlotForce> makeSlot(int writers) {
  auto slot = std::make_unique<SlotForce>();
  slot->reset(kf::DeviceSpec{});
  for (int i = 0; i < writers; ++i) slot->registerWriter();
  return slot;
}

}  // namespace

TEST_CASE("one writer: its own frames, exactly, framed in its own block") {
  auto slot = makeSlot(1);
  Recorder sink;
  kf::ForceFramer reference(0.001, 0.14, 1.4);
  std::vector<Frame> expected;
  auto expect = [&](double t, float f) { expected.push_back({t, f, 0}); };
  std::vector<float> force(64);
  for (int64_t b = 0; b < 750; ++b) {  // 1 s
    const BlockClock clock = clockOf(b);
    for (int i = 0; i < 64; ++i) force[i] = 0.2f + 0.6f * ((b * 64 + i) / 480 % 2);  // 50 Hz square
    sink.currentBlock = b;
    CHECK(slot->write(clock, force.data(), 64, sink));
    reference.process(clock.startS, clock.sampleDurS, force.data(), 64, nullptr, expect);
  }
  REQUIRE(sink.frames.size() == expected.size());
  CHECK(sink.frames.size() >= 999);
  for (size_t i = 0; i < expected.size(); ++i) {
    REQUIRE(sink.frames[i].timeS == expected[i].timeS);
    REQUIRE(sink.frames[i].forceN == expected[i].forceN);
  }
}

TEST_CASE("several writers: one frame per millisecond, forces above the minimum add up") {
  for (int writers : {2, 3, 8}) {
    auto slot = makeSlot(writers);
    Recorder sink;
    std::vector<float> idle(64, 0.14f), a(64, 0.3f), b(64, 1.0f);
    for (int64_t blk = 0; blk < 750; ++blk) {
      const BlockClock clock = clockOf(blk);
      sink.currentBlock = blk;
      for (int w = 0; w < writers; ++w) {
        const std::vector<float>& f = w == 0 ? a : (w == 1 ? b : idle);
        const bool last = slot->write(clock, f.data(), 64, sink);
        CHECK(last == (w == writers - 1));  // framed by the last writer: no added latency
      }
    }
    // 750 blocks of 64 samples at 48 kHz = 1.0 s: 1000 frames, not writers x 1000.
    CHECK(sink.frames.size() == 1000);
    for (size_t i = 1; i < sink.frames.size(); ++i)
      REQUIRE(sink.frames[i].timeS - sink.frames[i - 1].timeS == Approx(0.001).margin(1e-12));
    for (const Frame& f : sink.frames) REQUIRE(f.forceN == Approx(0.14 + 0.16 + 0.86).epsilon(1e-6));
  }
}

TEST_CASE("idle writers stay at the floor together, NaN, Inf and forces below the minimum add nothing") {
  auto slot = makeSlot(4);
  Recorder sink;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> idle(64, 0.14f), low(64, 0.0f), bad(64, nan), huge(64, inf);
  for (int64_t blk = 0; blk < 75; ++blk) {
    const BlockClock clock = clockOf(blk);
    slot->write(clock, idle.data(), 64, sink);
    slot->write(clock, low.data(), 64, sink);
    slot->write(clock, bad.data(), 64, sink);
    slot->write(clock, huge.data(), 64, sink);
  }
  REQUIRE(sink.frames.size() == 100);
  for (const Frame& f : sink.frames) REQUIRE(f.forceN == 0.14f);
}

TEST_CASE("the sum is limited to the device's maximum") {
  auto slot = makeSlot(3);
  Recorder sink;
  std::vector<float> strong(64, 1.0f);
  for (int64_t blk = 0; blk < 75; ++blk)
    for (int w = 0; w < 3; ++w) slot->write(clockOf(blk), strong.data(), 64, sink);
  for (const Frame& f : sink.frames) REQUIRE(f.forceN == 1.4f);
}

TEST_CASE("a crossfade of writers gives frames between old and new force, never alternating") {
  // Two writers with equal-power-free linear gains, as a crossfade that has its envelope in
  // the force: old 0.3 N fading out above the floor, new 1.0 N fading in.
  auto slot = makeSlot(2);
  Recorder sink;
  std::vector<float> oldF(64), newF(64);
  const int fadeBlocks = 375;  // 0.5 s
  for (int64_t blk = 0; blk < fadeBlocks; ++blk) {
    for (int i = 0; i < 64; ++i) {
      const double g = (blk * 64 + i) / (fadeBlocks * 64.0);
      oldF[i] = static_cast<float>(0.14 + (1 - g) * 0.16);
      newF[i] = static_cast<float>(0.14 + g * 0.86);
    }
    slot->write(clockOf(blk), oldF.data(), 64, sink);
    slot->write(clockOf(blk), newF.data(), 64, sink);
  }
  REQUIRE(sink.frames.size() == 500);
  int reversals = 0;
  for (size_t i = 0; i < sink.frames.size(); ++i) {
    REQUIRE(sink.frames[i].forceN >= 0.3f - 1e-4f);
    REQUIRE(sink.frames[i].forceN <= 1.0f + 1e-4f);
    if (i >= 2) {
      const float d1 = sink.frames[i - 1].forceN - sink.frames[i - 2].forceN;
      const float d2 = sink.frames[i].forceN - sink.frames[i - 1].forceN;
      if (d1 * d2 < 0) ++reversals;
    }
  }
  CHECK(reversals == 0);
}

TEST_CASE("a registered writer that does not run (paused): blocks are framed one block late, none lost") {
  auto slot = makeSlot(2);
  Recorder sink;
  std::vector<float> f(64, 0.5f);
  for (int64_t blk = 0; blk < 75; ++blk) {
    sink.currentBlock = blk;
    CHECK_FALSE(slot->write(clockOf(blk), f.data(), 64, sink));
  }
  // Block 74 is still open; everything before it was framed, each frame once.
  const double framedUntilS = 74 * 64 / 48000.0;
  CHECK(sink.frames.size() == static_cast<size_t>(std::floor(framedUntilS / 0.001)));
  for (const Frame& fr : sink.frames) REQUIRE(fr.forceN == 0.5f);
  for (const Frame& fr : sink.frames) REQUIRE(fr.emittedInBlock * 64 / 48000.0 >= fr.timeS + 0.001 - 1e-12);
}

TEST_CASE("a writer freed in the middle of a block frames the block if the others have written") {
  auto slot = makeSlot(2);
  Recorder sink;
  std::vector<float> f(64, 0.5f);
  for (int64_t blk = 0; blk < 10; ++blk) {
    slot->write(clockOf(blk), f.data(), 64, sink);
    slot->write(clockOf(blk), f.data(), 64, sink);
  }
  const size_t before = sink.frames.size();
  CHECK_FALSE(slot->write(clockOf(10), f.data(), 64, sink));  // the first writer of block 10
  slot->unregisterWriter();                                   // the second goes away
  slot->writerGone(clockOf(10), sink);
  CHECK(slot->framedBlock() == 10);
  CHECK(sink.frames.size() > before);
  // From then on the remaining writer frames its blocks itself.
  CHECK(slot->write(clockOf(11), f.data(), 64, sink));
}

TEST_CASE("the last writer gone mid-frame: its part of a frame is dropped, a writer later starts afresh") {
  // 64 samples at 48 kHz: block 10 ends 14.67 ms in, two thirds of the way into frame 14.
  auto slot = makeSlot(1);
  Recorder sink;
  std::vector<float> f(64, 1.0f), g(64, 0.5f);
  for (int64_t blk = 0; blk <= 10; ++blk) CHECK(slot->write(clockOf(blk), f.data(), 64, sink));
  CHECK(sink.frames.back().timeS == Approx(0.013));  // frame 14 is in progress
  slot->unregisterWriter();
  slot->writerGone(clockOf(11), sink);
  const size_t before = sink.frames.size();
  // 150 ms later a new writer starts: every frame it sends is its own, none from before.
  slot->registerWriter();
  for (int64_t blk = 123; blk < 130; ++blk) CHECK(slot->write(clockOf(blk), g.data(), 64, sink));
  REQUIRE(sink.frames.size() > before);
  for (size_t i = before; i < sink.frames.size(); ++i) {
    INFO("frame " << i << " at " << sink.frames[i].timeS << " s");
    CHECK(sink.frames[i].timeS >= clockOf(123).startS - 0.001);
    CHECK(sink.frames[i].forceN == Approx(0.5));
  }
}

TEST_CASE("control-rate writers and 44.1 to 192 kHz: still one frame per millisecond") {
  for (double rate : {44100.0, 96000.0, 192000.0}) {
    auto slot = makeSlot(2);
    Recorder sink;
    std::vector<float> ar(64, 0.6f);
    const float kr = 0.4f;
    const int64_t blocks = static_cast<int64_t>(std::ceil(rate / 64));  // >= 1 s
    for (int64_t blk = 0; blk < blocks; ++blk) {
      slot->write(clockOf(blk, 64, rate), ar.data(), 64, sink);
      slot->write(clockOf(blk, 64, rate), &kr, 1, sink);
    }
    const double endS = blocks * 64 / rate;
    CHECK(sink.frames.size() == static_cast<size_t>(std::floor(endS / 0.001 + 1e-9)));
    for (const Frame& f : sink.frames) REQUIRE(f.forceN == Approx(0.14 + 0.46 + 0.26).epsilon(1e-6));
  }
}

TEST_CASE("a writer that registers after the block was framed joins from the next block, no frame twice") {
  // scsynth constructs a synth's units in its first calc: a new writer later in node order
  // registers after the others of that block have framed it.
  auto slot = makeSlot(1);
  Recorder sink;
  std::vector<float> a(64, 0.3f), b(64, 1.0f);
  for (int64_t blk = 0; blk < 75; ++blk) {
    slot->write(clockOf(blk), a.data(), 64, sink);
    if (blk == 10) slot->registerWriter();  // b's constructor, after a has framed block 10
    if (blk >= 10) slot->write(clockOf(blk), b.data(), 64, sink);
  }
  REQUIRE(sink.frames.size() == 100);
  for (size_t i = 1; i < sink.frames.size(); ++i)
    REQUIRE(sink.frames[i].timeS - sink.frames[i - 1].timeS == Approx(0.001).margin(1e-12));
  CHECK(sink.frames[5].forceN == Approx(0.3));
  CHECK(sink.frames[20].forceN == Approx(1.16));
}

// --- weights (FrictionOut's fade: by default its synth's gate envelope) -------------------------

TEST_CASE("a writer's weight scales its force above the minimum, clamped to [0, 1], NaN and Inf as 0") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  // weight -> expected frame for a writer asking 0.8 N (0.66 N above the minimum of 0.14 N)
  const std::vector<std::pair<float, float>> cases = {{1.0f, 0.8f},  {0.5f, 0.47f},  {0.0f, 0.14f},   {1.5f, 0.8f},
                                                      {1e30f, 0.8f}, {-0.5f, 0.14f}, {-1e30f, 0.14f}, {nan, 0.14f},
                                                      {inf, 0.14f},  {-inf, 0.14f}};
  for (const auto& [weight, expected] : cases) {
    INFO("weight " << weight);
    for (int fadeSamples : {1, 64}) {  // control-rate and audio-rate weights
      auto slot = makeSlot(1);
      Recorder sink;
      std::vector<float> force(64, 0.8f), fade(64, weight);
      for (int64_t blk = 0; blk < 75; ++blk)
        slot->write(clockOf(blk), force.data(), 64, fade.data(), fadeSamples, sink);
      REQUIRE(sink.frames.size() == 100);
      for (const Frame& f : sink.frames) REQUIRE(f.forceN == Approx(expected).margin(1e-6));
    }
  }
}

TEST_CASE("a weight of 1 is the writer's own force, exactly, and a weight never lifts a force below the minimum") {
  auto slot = makeSlot(2);
  Recorder sink;
  std::vector<float> force(64, 0.731f), low(64, 0.05f), one(64, 1.0f), two(64, 2.0f);
  for (int64_t blk = 0; blk < 75; ++blk) {
    slot->write(clockOf(blk), force.data(), 64, one.data(), 64, sink);
    slot->write(clockOf(blk), low.data(), 64, two.data(), 64, sink);  // 0.05 N counts as the minimum
  }
  for (const Frame& f : sink.frames) REQUIRE(f.forceN == 0.731f);
}

namespace {

// JITLib's crossfade (EnvGate, curve 'sin'): the new version rises 0 -> 1 on a half cosine over
// the fade, the old one falls 1 -> 0 on the same shape, both from the same block. Their weights
// are w and 1 - w at every sample. Returns the frames of two writers asking oldN and newN,
// fading over fadeS after 0.1 s at full weight of the old one; `sampleRate` per sample weights
// (audio rate), `controlRate` one weight per block (EnvGen.kr, as EnvGate is).
std::vector<Frame> crossfade(float oldN, float newN, double fadeS, bool controlRate) {
  auto slot = makeSlot(2);
  Recorder sink;
  const double rate = 48000.0;
  std::vector<float> oldF(64, oldN), newF(64, newN), wOld(64), wNew(64);
  const int64_t blocks = static_cast<int64_t>((0.2 + fadeS) * rate / 64);
  for (int64_t blk = 0; blk < blocks; ++blk) {
    for (int i = 0; i < 64; ++i) {
      const int64_t n = blk * 64 + (controlRate ? 0 : i);
      const double x = std::clamp((n / rate - 0.1) / fadeS, 0.0, 1.0);
      wNew[i] = static_cast<float>(0.5 - 0.5 * std::cos(std::acos(-1.0) * x));
      wOld[i] = 1.0f - wNew[i];
    }
    sink.currentBlock = blk;
    slot->write(clockOf(blk), oldF.data(), 64, wOld.data(), controlRate ? 1 : 64, sink);
    slot->write(clockOf(blk), newF.data(), 64, wNew.data(), controlRate ? 1 : 64, sink);
  }
  return sink.frames;
}

}  // namespace

TEST_CASE("a crossfade of complementary weights between two 0.5 N versions stays at 0.5 N, not their sum 0.86 N") {
  for (bool controlRate : {false, true}) {
    INFO((controlRate ? "control-rate" : "audio-rate") << " weights");
    const std::vector<Frame> frames = crossfade(0.5f, 0.5f, 2.0, controlRate);
    REQUIRE(frames.size() >= 2199);
    // w + (1 - w) is 1 within a float's rounding (6e-8 of 0.36 N above the minimum): 1e-6 N.
    for (const Frame& f : frames) REQUIRE(f.forceN == Approx(0.5).margin(1e-6));
  }
}

TEST_CASE("a crossfade from 0.5 N to 0.8 N moves from old to new, monotonic, never above the larger") {
  for (bool controlRate : {false, true}) {
    INFO((controlRate ? "control-rate" : "audio-rate") << " weights");
    const std::vector<Frame> frames = crossfade(0.5f, 0.8f, 2.0, controlRate);
    float hi = 0;
    for (size_t i = 0; i < frames.size(); ++i) {
      hi = std::max(hi, frames[i].forceN);
      REQUIRE(frames[i].forceN >= 0.5f - 1e-6f);
      REQUIRE(frames[i].forceN <= 0.8f + 1e-6f);
      if (i > 0) REQUIRE(frames[i].forceN >= frames[i - 1].forceN - 1e-6f);
      if (frames[i].timeS < 0.1 - 0.002) REQUIRE(frames[i].forceN == Approx(0.5).margin(1e-6));
      if (frames[i].timeS > 2.1 + 0.002) REQUIRE(frames[i].forceN == Approx(0.8).margin(1e-6));
    }
    CHECK(hi == Approx(0.8).margin(1e-6));
    // Halfway through the fade, halfway between the forces (the half cosine's midpoint).
    for (const Frame& f : frames)
      if (std::abs(f.timeS + 0.0005 - 1.1) < 0.0006) CHECK(f.forceN == Approx(0.65).margin(2e-3));
  }
}
