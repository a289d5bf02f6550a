// TrajectoryReconstructor::render fills the samples between two reports stretch by stretch
// (fade, extrapolation, held, stale, rest), with the stretches' ends found once per run. Whatever
// the block sizes, the output must be the per-sample rule's, bit for bit: here one reconstructor
// renders blocks of random sizes and a copy renders the same samples one call per sample, at the
// same times, across report takes, late reports, gaps that cross the stale and fade ends, a
// change of the measured update rate, all three modes and 44.1-192 kHz.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "TrajectoryReconstructor.hpp"

using kf::TrajectoryMode;
using kf::TrajectoryReconstructor;

namespace {

constexpr double kCountMm = 0.021;
constexpr double kRateHz = 125.0;
constexpr double kIntervalS = 1.0 / kRateHz;

struct Report {
  double timeS, dxMm, dyMm;
};

// Bursts of reports every T (jittered off the sample grid), then a gap of 1.2-4.5 T: the gaps
// carry the phase across 1, 1.5, 2 and 3 T within one run. From 0.4 s on the mouse reports at
// 1 kHz, so the measured rate replaces the nominal T. Some reports are late (timed before the
// block they arrive in), and some fall on a sample's time (taken with s = 0 there).
// Draws from mt19937's raw output, which the standard fixes, mapped here rather than by the
// <random> distributions, whose draws differ between libstdc++ and libc++: the same schedule on
// every library.
int drawInt(std::mt19937& rng, int lo, int hi) {
  return lo + static_cast<int>(rng() % static_cast<uint32_t>(hi - lo + 1));
}
double drawReal(std::mt19937& rng, double lo, double hi) { return lo + (hi - lo) * (rng() / 4294967296.0); }

std::vector<Report> reportSchedule(std::mt19937& rng, double durationS, double sampleDurS) {
  auto counts = [&] { return drawInt(rng, -12, 12); };
  std::vector<Report> reports;
  double t = 0.003;
  while (t < durationS) {
    const double intervalS = t < 0.4 ? kIntervalS : 0.001;
    for (int k = drawInt(rng, 1, 6); k > 0; --k, t += intervalS) {
      double timeS = t + drawReal(rng, -0.1, 0.1) * intervalS;
      if (k % 3 == 0) timeS = std::round(timeS / sampleDurS) * sampleDurS;
      const double dxMm = counts() * kCountMm, dyMm = counts() * kCountMm;  // x drawn first
      reports.push_back({timeS, dxMm, dyMm});
    }
    t += drawReal(rng, 1.2, 4.5) * intervalS;
  }
  return reports;
}

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("TrajectoryReconstructor: blocks of any size render bit for bit as sample by sample", "[trajectory]") {
  std::mt19937 rng(25);
  const double durationS = 0.6;
  for (double sampleRateHz : {44100.0, 48000.0, 96000.0, 192000.0}) {
    for (TrajectoryMode mode : {TrajectoryMode::Hold, TrajectoryMode::Linear, TrajectoryMode::Predictive}) {
      INFO("rate " << sampleRateHz << " Hz, mode " << static_cast<int>(mode));
      const double durS = 1.0 / sampleRateHz;
      const std::vector<Report> reports = reportSchedule(rng, durationS, durS);
      const int total = static_cast<int>(durationS * sampleRateHz);
      const double originXMm = 12.5, originYMm = -3.0;
      TrajectoryReconstructor blocks(kRateHz, mode);
      std::vector<float> out[4], ref[4];
      for (auto& v : out) v.resize(total);
      for (auto& v : ref) v.resize(total);
      size_t next = 0;
      for (int start = 0; start < total;) {
        const int choice = drawInt(rng, 0, 3);
        const int n = std::min(total - start, choice == 0 ? 2048 : choice == 1 ? 256 : drawInt(rng, 1, 70));
        const double startS = start * durS;
        // Every report timed before the block's end; a few of them hold back one more block (late).
        while (next < reports.size() && reports[next].timeS < startS + n * durS && drawInt(rng, 0, 3) != 0) {
          blocks.addReport(reports[next].timeS, reports[next].dxMm, reports[next].dyMm);
          ++next;
        }
        TrajectoryReconstructor perSample = blocks;
        blocks.render(startS, durS, n, originXMm, originYMm, out[0].data() + start, out[1].data() + start,
                      out[2].data() + start, out[3].data() + start);
        for (int i = 0; i < n; ++i) {
          perSample.render(startS + i * durS, durS, 1, originXMm, originYMm, ref[0].data() + start + i,
                           ref[1].data() + start + i, ref[2].data() + start + i, ref[3].data() + start + i);
          // The rendered* values come from the per-sample rule itself (positionAt, speedAt), not
          // from the stretches: a sample alone must be exactly that.
          REQUIRE(sameBits(ref[0][start + i], static_cast<float>(perSample.renderedXMm() - originXMm)));
          REQUIRE(sameBits(ref[1][start + i], static_cast<float>(perSample.renderedYMm() - originYMm)));
          REQUIRE(sameBits(ref[2][start + i], static_cast<float>(perSample.renderedSpeedXMmPerS())));
          REQUIRE(sameBits(ref[3][start + i], static_cast<float>(perSample.renderedSpeedYMmPerS())));
        }
        REQUIRE(blocks.renderedXMm() == perSample.renderedXMm());
        REQUIRE(blocks.renderedYMm() == perSample.renderedYMm());
        REQUIRE(blocks.renderedSpeedXMmPerS() == perSample.renderedSpeedXMmPerS());
        REQUIRE(blocks.renderedSpeedYMmPerS() == perSample.renderedSpeedYMmPerS());
        REQUIRE(blocks.reportsTaken() == perSample.reportsTaken());
        start += n;
      }
      for (int c = 0; c < 4; ++c) {
        for (int i = 0; i < total; ++i) {
          if (sameBits(out[c][i], ref[c][i])) continue;
          INFO("output " << c << ", sample " << i << ": " << out[c][i] << " in blocks, " << ref[c][i] << " alone");
          REQUIRE(sameBits(out[c][i], ref[c][i]));
        }
      }
      // Samples inside a fade of speed (it changes on both sides; a take changes it once): the
      // gaps did carry runs across the stale and rest ends.
      int fadingSamples = 0;
      for (int i = 1; i + 1 < total; ++i)
        if (ref[2][i - 1] != ref[2][i] && ref[2][i] != ref[2][i + 1]) ++fadingSamples;
      CHECK(fadingSamples > 500);
      CHECK(blocks.updateIntervalS() < kIntervalS / 2);  // the 1 kHz reports replaced the nominal T
    }
  }
}
