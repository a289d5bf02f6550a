// The friction patterns (dsp/*Pattern*, SpeedFriction, FrictionPatternCore) against their
// definitions, written again here independently of the code under test: ramps, periodicity,
// direction, revisits, the anti-aliasing figures, bad inputs, extreme parameters, sample rates.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <vector>

#include "ForceFrameSpectrum.hpp"
#include "patterns/FrictionPatternCore.hpp"

using namespace kf::patterns;

namespace {

// 1 ms frame means of a force at 48 kHz (the device's force frames), and the largest amplitude
// of their spectrum away from DC: shared with bench/patterns_bench.cpp.
using kf::spectrum::frames;
using kf::spectrum::largestNonDcAmplitude;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kMinN = 0.14, kMaxN = 0.5;

double frac(double x) { return x - std::floor(x); }

// The grating of the header's definition, at cycle fraction f.
double gratingDef(double f, double duty, double e) {
  if (f < e) return f / e;
  if (f < duty) return 1.0;
  if (f < duty + e) return 1.0 - (f - duty) / e;
  return 0.0;
}

// The bump's climb rate in the direction of motion over its steepest: max(0, dir * dh/du) / (pi / omega).
double bumpDef(double f, double omega, int dir, bool valleys) {
  if (f >= omega) return 0.0;
  const double s = std::sin(2 * kPi * f / omega) * (valleys ? -1 : 1);
  return std::max(0.0, dir * s);
}

double detentDef(double f, double crest, int dir) {
  const double g = dir > 0 ? f : frac(-f);
  return g < crest ? g / crest : 0.0;
}

// The mean of def over [x0, x1] (mm) by the midpoint rule on 20000 points: the box filter,
// computed without the closed forms under test.
template <class Def>
double boxMean(Def def, double x0, double x1) {
  if (x0 == x1) return def(x1);
  const int n = 20000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += def(x0 + (x1 - x0) * (i + 0.5) / n);
  return sum / n;
}

// Runs a core over positions, one block of 64 at a time with the parameters set per block.
std::vector<float> run(FrictionPatternCore& core, const std::vector<float>& x, double p1, double p2, double p3,
                       const std::vector<float>* height = nullptr) {
  std::vector<float> force(x.size());
  for (size_t i = 0; i < x.size(); i += 64) {
    const int n = static_cast<int>(std::min<size_t>(64, x.size() - i));
    core.setParameters(p1, p2, p3, x[i]);
    core.process(x.data() + i, 1, height ? height->data() + i : nullptr, 1, force.data() + i, n);
  }
  return force;
}

// A ramp at speedMmPerS from x0 for seconds, at sampleRate.
std::vector<float> ramp(double x0, double speedMmPerS, double seconds, double sampleRate) {
  std::vector<float> x(static_cast<size_t>(seconds * sampleRate));
  for (size_t i = 0; i < x.size(); ++i) x[i] = static_cast<float>(x0 + speedMmPerS * i / sampleRate);
  return x;
}

FrictionPatternCore core(PatternKind kind, double sampleRate = 48000, bool antialias = true) {
  FrictionPatternCore c(kind, sampleRate);
  c.setForceRange({kMinN, kMaxN});
  c.setAntialias(antialias);
  return c;
}

double level(float forceN) { return (forceN - kMinN) / (kMaxN - kMinN); }

}  // namespace

TEST_CASE("grating: point values on a ramp are the definition, and the box filter is its mean over the travel") {
  const double period = 2.0, duty = 0.3, edge = 0.25;
  auto def = [&](double x) { return gratingDef(frac(x / period), duty, edge / period); };
  const auto x = ramp(-3.0, 1.0, 2.0, 48000);
  auto raw = core(PatternKind::Grating, 48000, false);
  const auto f = run(raw, x, period, duty, edge);
  for (size_t i = 0; i < x.size(); i += 29) REQUIRE(f[i] == Approx(kMinN + (kMaxN - kMinN) * def(x[i])).margin(1e-6));
  auto boxed = core(PatternKind::Grating);
  const auto g = run(boxed, x, period, duty, edge);
  // 1 mm/s over 2 mm is 0.5 Hz: harmonic 1000 is at the frames' 500 Hz, past twice the grating's
  // kSharp (321 for an edge of 1/8 period, PatternTravel.hpp), so no harmonic is weighted: the
  // level is the box mean itself.
  for (size_t i = 48; i < x.size(); i += 389)
    REQUIRE(level(g[i]) == Approx(boxMean(def, x[i - 48], x[i])).margin(2e-6));
}

TEST_CASE("grating: integral of one period is the duty, the level is periodic and far from 0 stays exact") {
  GratingPattern p;
  p.set(0.2, 0.4, 0.03, 0.0);
  CHECK(p.integralTo(0.999999999) == Approx(0.4).margin(1e-8));
  for (double x0 : {0.013, 1.5, 1e6 + 0.071}) {
    // 0.1 mm/s: slow enough for the closed form (harmonic 1000 at the frames' 500 Hz, past twice
    // kSharp, 294 for an edge of 0.15 period).
    Travel a{x0, x0 + 1e-4, 1, 0.1, 1e-3}, b{x0 + 0.2 * 7, x0 + 0.2 * 7 + 1e-4, 1, 0.1, 1e-3};
    CHECK(p.level(a, true) == Approx(p.level(b, true)).margin(1e-7));
    const double want = boxMean([](double x) { return gratingDef(frac(x / 0.2), 0.4, 0.15); }, x0, x0 + 1e-4);
    CHECK(p.level(a, true) == Approx(want).margin(1e-6));
  }
}

TEST_CASE("anti-aliasing: 300 mm/s over a 0.2 mm grating has no alias in the force frames and 5 mm/s renders it") {
  // 300 mm/s over 0.2 mm is 1500 Hz, three times the frames' 500 Hz Nyquist frequency: the
  // band-limited grating is its mean (duty 0.5: 0.32 N) and the frames are constant but for
  // float rounding of the level (0.36 N * 2^-24 ~ 2e-8 N): the stated level is 1e-6 N. Without
  // anti-aliasing the 1 ms frames of the 1500 Hz square wave alias to 500 Hz; measured 0.044 N
  // (assert > 0.02 N: this test does see an alias; with it, measured exactly 0).
  const auto fast = ramp(0.0, 300.0, 0.3, 48000);
  auto on = core(PatternKind::Grating), off = core(PatternKind::Grating, 48000, false);
  const double onAlias = largestNonDcAmplitude(frames(run(on, fast, 0.2, 0.5, 0.02), 480));
  const double offAlias = largestNonDcAmplitude(frames(run(off, fast, 0.2, 0.5, 0.02), 480));
  INFO("alias with " << onAlias << " N, without " << offAlias << " N");
  CHECK(onAlias < 1e-6);
  CHECK(offAlias > 0.02);
  // 5 mm/s over 0.2 mm is 25 Hz: 19 harmonics below 500 Hz, weighted by the spline whose kernel
  // (sinc^4, zeros every 2 ms) is far shorter than the 16 ms flat top and bottom: the full swing
  // but for the kernel's tails (measured 1e-4 N short; 5e-4 N allowed, 1% of the 0.36 N swing).
  const auto slow = ramp(0.0, 5.0, 0.2, 48000);
  auto slowOn = core(PatternKind::Grating);
  const auto s = run(slowOn, slow, 0.2, 0.5, 0.02);
  const auto [lo, hi] = std::minmax_element(s.begin() + 48, s.end());
  CHECK(*lo == Approx(kMinN).margin(5e-4));
  CHECK(*hi == Approx(kMaxN).margin(5e-4));
}

TEST_CASE("anti-aliasing follows the force rate: at 8 kHz frames a 1500 Hz grating is kept and a 6 kHz one removed") {
  // A device framing force at 8 kHz (forceFramePeriodS 0.000125, a 2.1 board): the pattern's band
  // limit moves with it (full up to 2 kHz, none from 4 kHz). Frames: 6 samples at 48 kHz.
  const double framePeriodS = 0.000125;
  auto framesOf = [](const std::vector<float>& f, size_t from, size_t perFrame) {
    std::vector<double> out;
    for (size_t i = from; i + perFrame <= f.size(); i += perFrame) {
      double sum = 0;
      for (size_t k = 0; k < perFrame; ++k) sum += f[i + k];
      out.push_back(sum / perFrame);
    }
    return out;
  };
  auto at8k = [&](bool antialias) {  // a grating framed at 8 kHz
    FrictionPatternCore c(PatternKind::Grating, 48000, framePeriodS);
    c.setForceRange({kMinN, kMaxN});
    c.setAntialias(antialias);
    return c;
  };
  const auto fast = ramp(0.0, 300.0, 0.3, 48000);
  // The pattern is made per frame: at 8 kHz frames and 48 kHz it is, sample for sample, the
  // pattern at 1 kHz frames and 6 kHz moved 8 times slower (the same travel per sample and per
  // frame). So its band limit is the 1 kHz one scaled by 8: 0.2 mm at 300 mm/s (1500 Hz) is
  // rendered as the paper's frames render 37.5 mm/s (187.5 Hz).
  auto on8k = at8k(true);
  const auto force8k = run(on8k, fast, 0.2, 0.5, 0.02);
  FrictionPatternCore slowCore(PatternKind::Grating, 6000, 0.001);
  slowCore.setForceRange({kMinN, kMaxN});
  const auto force1k = run(slowCore, ramp(0.0, 37.5, 0.3, 6000), 0.2, 0.5, 0.02);
  double worst = 0;
  for (size_t i = 0; i < std::min(force8k.size(), force1k.size()); ++i)
    worst = std::max(worst, std::fabs(static_cast<double>(force8k[i]) - force1k[i]));
  INFO("8 kHz frames at 300 mm/s against 1 kHz frames at 37.5 mm/s: largest difference " << worst << " N");
  CHECK(worst < 1e-6);  // float positions and forces: their rounding only
  // And it is there: the 1500 Hz line in the 8 kHz frames is most of the square wave's
  // fundamental ((4 / pi) x 0.18 N = 0.23 N, less the pattern's own spline taper), where the
  // paper's 1 ms pattern has removed it entirely (its frames are the grating's mean).
  auto on1k = core(PatternKind::Grating);
  const double kept = largestNonDcAmplitude(framesOf(force8k, 480, 6));
  const double at1k = largestNonDcAmplitude(frames(run(on1k, fast, 0.2, 0.5, 0.02), 480));
  INFO("1500 Hz line in the 8 kHz frames " << kept << " N, in the 1 ms frames " << at1k << " N");
  CHECK(kept > 0.05);
  CHECK(at1k < 1e-6);
  // 0.05 mm at 300 mm/s: 6 kHz, over the 8 kHz frames' 4 kHz Nyquist frequency: removed with
  // anti-aliasing (its mean; float rounding only), folded to 2 kHz without.
  auto fineOn = at8k(true), fineOff = at8k(false);
  const double aliasOn = largestNonDcAmplitude(framesOf(run(fineOn, fast, 0.05, 0.5, 0.005), 480, 6));
  const double aliasOff = largestNonDcAmplitude(framesOf(run(fineOff, fast, 0.05, 0.5, 0.005), 480, 6));
  INFO("6 kHz grating in the 8 kHz frames: alias with " << aliasOn << " N, without " << aliasOff << " N");
  CHECK(aliasOn < 1e-6);
  CHECK(aliasOff > 0.02);
}

// The amplitude (N) at frequencyHz of 1 ms frames (frame rate 1 kHz), by a DFT at that frequency
// under a 4-term Blackman-Harris window (sidelobes below -92 dB: a 0.2 N line 8 Hz away or more
// leaks < 5e-6 N into it at 1 s of frames).
double amplitudeAt(const std::vector<double>& v, double frequencyHz) {
  const size_t n = v.size();
  std::complex<double> acc = 0;
  double wsum = 0;
  for (size_t i = 0; i < n; ++i) {
    const double p = 2 * kPi * i / n;
    const double w = 0.35875 - 0.48829 * std::cos(p) + 0.14128 * std::cos(2 * p) - 0.01168 * std::cos(3 * p);
    acc += v[i] * w * std::polar(1.0, -2 * kPi * frequencyHz * i / 1000.0);
    wsum += w;
  }
  return 2 * std::abs(acc) / wsum;
}

TEST_CASE("anti-aliasing: no harmonic of a sharp grating folds into the frames, 20 to 300 mm/s") {
  // A grating moved at v over period P has lines at k v / P. Every line above the frames' 500 Hz
  // Nyquist frequency folds to |k v / P - 1000 m|; each must be gone (exact band limit per
  // harmonic). What is left there: float rounding of the force (0.36 N * 2^-24 ~ 2e-8 N) and the
  // window's leakage from the lines kept (< 5e-6 N, lines 8 Hz apart or more, amplitudeAt), so the
  // stated level is 1e-5 N (measured worst 3.7e-7 N). The fade on the fundamental alone left
  // 0.0195 N at 36 mm/s (540 Hz folded to 460 Hz) and 0.021 N at 60 mm/s duty 0.3 (600 -> 400 Hz).
  const double period = 0.2;
  for (double speed : {20.0, 27.3, 36.0, 47.9, 60.0, 83.7, 117.1, 163.3, 231.9, 300.0}) {
    for (double duty : {0.3, 0.5}) {
      for (double edge : {0.0, 0.02}) {
        const auto x = ramp(0.013, speed, 1.05, 48000);
        auto c = core(PatternKind::Grating);
        const auto fr = frames(run(c, x, period, duty, edge), 2400);
        std::vector<double> d(fr.begin(), fr.begin() + 1000);
        double mean = 0;
        for (double a : d) mean += a / d.size();
        for (double& a : d) a -= mean;
        const double f1 = speed / period;
        for (int k = 1; k * f1 < 24000; ++k) {
          if (k * f1 <= 500) continue;
          const double folded = std::fabs(k * f1 - 1000 * std::round(k * f1 / 1000));
          bool nearKept = folded < 8;  // DC
          for (int j = 1; j * f1 <= 500; ++j) nearKept = nearKept || std::fabs(folded - j * f1) < 8;
          if (nearKept) continue;  // on a line kept: not separable (e.g. 40 mm/s, 600 -> 400 Hz)
          const double a = amplitudeAt(d, folded);
          INFO(speed << " mm/s duty " << duty << " edge " << edge << ": harmonic " << k << " (" << k * f1
                     << " Hz) folded to " << folded << " Hz, " << a << " N");
          REQUIRE(a < 1e-5);
        }
      }
    }
  }
}

TEST_CASE("the fade is 1 up to a quarter of the frame rate, 0 from half of it, and continuous") {
  CHECK(bandLimitGain(250.0, 1e-3) == 1.0);
  CHECK(bandLimitGain(500.0, 1e-3) == 0.0);
  CHECK(bandLimitGain(375.0, 1e-3) == Approx(0.5));
  CHECK(bandLimitGain(499.999, 1e-3) < 1e-9);
  CHECK(bandLimitGain(250.001, 1e-3) > 1 - 1e-9);
}

TEST_CASE(
    "bumps: resist going up, free going down, from either side and the box filter is the mean of the definition") {
  const double period = 4.0, width = 2.0, omega = width / period;
  for (bool valleys : {false, true}) {
    for (int dir : {1, -1}) {
      // 2 mm/s over 4 mm: harmonic 1000 at the frames' 500 Hz, past twice kSharp (329 for omega
      // 0.5, PatternTravel.hpp): the closed form.
      const auto x = ramp(dir > 0 ? -1.0 : 4.5, dir * 2.0, 2.25, 48000);
      auto c = core(PatternKind::Bumps);
      const auto f = run(c, x, period, width, valleys ? 1 : 0);
      for (size_t i = 48; i < x.size(); i += 397) {  // 272 travels of each run: every part of a bump
        auto def = [&](double p) { return bumpDef(frac(p / period), omega, dir, valleys); };
        REQUIRE(level(f[i]) == Approx(boxMean(def, x[i - 48], x[i])).margin(2e-6));
      }
      // Moving +, a bump resists on its first half (0..1 mm), moving - on its second (1..2 mm).
      const bool resistsFirstHalf = (dir > 0) != valleys;
      auto at = [&](double p) {
        size_t best = 0;
        for (size_t i = 0; i < x.size(); ++i)
          if (std::fabs(x[i] - p) < std::fabs(x[best] - p)) best = i;
        return level(f[best]);
      };
      CHECK(at(0.5) == Approx(resistsFirstHalf ? std::sin(kPi * 0.5) : 0.0).margin(0.01));
      CHECK(at(1.5) == Approx(resistsFirstHalf ? 0.0 : 1.0).margin(0.01));
      CHECK(at(3.0) == Approx(0.0).margin(1e-6));
    }
  }
}

TEST_CASE("detents: the counterforce builds to the crest then drops, and turning back is free") {
  const double spacing = 3.0, crest = 0.6;
  auto c = core(PatternKind::Detents, 48000, false);
  // +: 0 -> 2.5 mm; then back to 1 mm.
  std::vector<float> x = ramp(0.0, 10.0, 0.25, 48000);
  const auto back = ramp(2.5, -10.0, 0.15, 48000);
  x.insert(x.end(), back.begin(), back.end());
  const auto f = run(c, x, spacing, crest, 0);
  for (size_t i = 48; i < x.size(); ++i) {
    if (i >= 12000 && i < 12000 + 48) continue;  // the travel straddles the turn
    const int dir = x[i] > x[i - 48] ? 1 : -1;   // the core's direction: the sign of the travel
    REQUIRE(level(f[i]) == Approx(detentDef(frac(x[i] / spacing), crest, dir)).margin(1e-5));
  }
  // Going +, 1.5 mm into the cell: 1.5 / 3 / 0.6 = 0.83; going back at 2 mm (cycle 0.67, seen
  // from the other side 0.33 -> 0.56).
  CHECK(level(f[static_cast<size_t>(0.15 * 48000)]) == Approx(0.8333).margin(0.01));
  CHECK(level(f[12000 + 2400]) == Approx((1 - 2.0 / 3.0) / 0.6).margin(0.01));
  // The anti-aliased detents are the box mean of the same definition where that is the closed form:
  // creeping (0.01 mm/s over 3 mm: harmonic 150000 at the frames' 500 Hz, past twice kSharp, 40528
  // for the drop at the crest, PatternTravel.hpp). Faster, the 64-harmonic series (rounded).
  DetentPattern creeping;
  creeping.set(spacing, crest, 0);
  for (double x0 = 0.0; x0 < 3.0; x0 += 0.0371)
    REQUIRE(
        creeping.level(Travel{x0, x0 + 1e-5, 1, 0.01, 1e-3}, true) ==
        Approx(boxMean([&](double p) { return detentDef(frac(p / spacing), crest, 1); }, x0, x0 + 1e-5)).margin(2e-6));
}

TEST_CASE("texture: the definition written again, the same force at every revisit, whatever came between") {
  // splitmix64 and the sum of sines, as the header defines them.
  auto reference = [](double lo, double hi, uint64_t seed, double xMm) {
    uint64_t state = seed;
    auto next = [&state] {
      uint64_t z = (state += 0x9E3779B97F4A7C15ull);
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      return static_cast<double>((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
    };
    double sum = 0;
    for (int k = 0; k < 16; ++k) {
      const double f = lo + (hi - lo) * next(), phi = 2 * kPi * next();
      sum += std::sin(2 * kPi * f * xMm + phi);
    }
    return std::clamp(0.5 + sum / (6 * std::sqrt(8.0)), 0.0, 1.0);
  };
  for (double x : {0.0, 0.37, 12.5, -40.0, 1e5})
    CHECK(TexturePattern::at(0.5, 3, 42, x) == Approx(reference(0.5, 3, 42, x)).margin(1e-9));

  auto c = core(PatternKind::Texture, 48000, false);
  std::vector<float> x = ramp(0.0, 20.0, 0.5, 48000);  // 0 -> 10 mm
  const auto back = ramp(10.0, -35.0, 0.2, 48000);     // back to 3 mm, faster
  const auto again = ramp(3.0, 7.0, 0.5, 48000);       // forward again, slowly
  x.insert(x.end(), back.begin(), back.end());
  x.insert(x.end(), again.begin(), again.end());
  const auto f = run(c, x, 0.5, 3, 42);
  for (size_t i = 0; i < x.size(); i += 11)
    REQUIRE(f[i] == Approx(kMinN + (kMaxN - kMinN) * reference(0.5, 3, 42, x[i])).margin(1e-6));
  // Band-limited, a place visited at the same speed gives the same force, bit for bit.
  auto b = core(PatternKind::Texture);
  std::vector<float> y = ramp(0.0, 20.0, 0.3, 48000);
  const auto away = ramp(6.0, -20.0, 0.3, 48000);
  y.insert(y.end(), away.begin(), away.end());
  y.insert(y.end(), y.begin(), y.begin() + 14400);
  const auto g = run(b, y, 0.5, 3, 42);
  for (size_t i = 64; i < 14400; ++i) REQUIRE(g[i] == g[28800 + i]);
}

TEST_CASE("texture: a new seed crossfades over 50 ms, nothing jumps") {
  auto c = core(PatternKind::Texture);
  const auto x = ramp(0.0, 20.0, 0.4, 48000);
  std::vector<float> f(x.size());
  for (size_t i = 0; i < x.size(); i += 64) {
    c.setParameters(0.5, 3, i < 9600 ? 1 : 2, x[i]);
    c.process(x.data() + i, 1, nullptr, 0, f.data() + i, 64);
  }
  double worst = 0;
  for (size_t i = 49; i < x.size(); ++i) worst = std::max(worst, double(std::fabs(f[i] - f[i - 1])));
  // Measured 1.4e-4 N per sample at 20 mm/s (0.36 N of range, 3 cycles/mm at most): a jump of a
  // whole texture would be ~0.1 N.
  CHECK(worst < 2e-3);
  CHECK(f[9600 + 2400 + 64] ==
        Approx(kMinN + (kMaxN - kMinN) * TexturePattern::at(0.5, 3, 2, x[9600 + 2400 + 64])).margin(0.01));
}

TEST_CASE("texture: a second change during the crossfade waits for it to end, nothing steps") {
  // Seeds 1 -> 2 at 200 ms -> 3 at 220 ms (inside the first 50 ms fade) -> 4 at 240 ms. Per sample
  // the force may change by what the moving texture makes (the same run with no change: own) plus
  // the fade's own step, the range over the 2400 samples of the fade (0.36 N / 2400 = 1.5e-4 N).
  // Replacing the texture being faded in steps by the fade weight times the difference (~0.04 N).
  const auto x = ramp(0.0, 20.0, 0.5, 48000);
  auto render = [&](double fixedSeed) {  // fixedSeed 0: the changes above
    auto c = core(PatternKind::Texture);
    std::vector<float> f(x.size());
    for (size_t i = 0; i < x.size(); i += 64) {
      const double seed = fixedSeed > 0 ? fixedSeed : (i < 9600 ? 1 : (i < 10560 ? 2 : (i < 11520 ? 3 : 4)));
      c.setParameters(0.5, 3, seed, x[i]);
      c.process(x.data() + i, 1, nullptr, 0, f.data() + i, 64);
    }
    return f;
  };
  auto worstStep = [](const std::vector<float>& f) {
    double worst = 0;
    for (size_t i = 49; i < f.size(); ++i) worst = std::max(worst, double(std::fabs(f[i] - f[i - 1])));
    return worst;
  };
  const auto changed = render(0);
  double own = 0;
  for (double seed : {1, 2, 3, 4}) own = std::max(own, worstStep(render(seed)));
  CHECK(worstStep(changed) <= own + (kMaxN - kMinN) / 2400.0);
  // 1 -> 2 ends at 250 ms, then 2 -> 4 (the newest pending) ends at 300 ms: texture 4 alone, as if
  // it had been there from the start (a function of position and travel).
  const auto four = render(4);
  for (size_t i = 9600 + 2 * 2400 + 64; i < x.size(); ++i) REQUIRE(changed[i] == four[i]);
  CHECK(changed[9600 + 2400 + 64] != four[9600 + 2400 + 64]);
}

TEST_CASE("grating: a change of period keeps the phase under the puck") {
  GratingPattern p;
  p.set(1.0, 0.5, 0.05, 0.0);  // edge 0.05 mm: the same shape in both periods at cycle 0.3
  const double at = 37.3;
  Travel here{at, at, 1, 0, 1e-3};
  const double before = p.level(here, false);
  p.set(0.37, 0.5, 0.05, at);
  CHECK(p.level(here, false) == Approx(before).margin(1e-9));
  Travel further{at + 0.37, at + 0.37, 1, 0, 1e-3};
  CHECK(p.level(further, false) == Approx(before).margin(1e-9));
}

TEST_CASE("a NaN position at the anchor sample of a period change still keeps the phase under the puck") {
  // The puck rests at 37.3 mm; the block that changes the period 1 -> 0.37 mm starts with a NaN
  // (held: the puck is still at 37.3 mm). The force under the puck must not move.
  auto c = core(PatternKind::Grating, 48000, false);
  std::vector<float> x(256, 37.3f), f(256);
  x[128] = kNaN;
  for (size_t i = 0; i < x.size(); i += 64) {
    c.setParameters(i < 128 ? 1.0 : 0.37, 0.5, 0.05, x[i]);
    c.process(x.data() + i, 1, nullptr, 0, f.data() + i, 64);
  }
  for (size_t i = 1; i < f.size(); ++i) REQUIRE(f[i] == f[0]);
}

TEST_CASE(
    "viscous rises linearly with speed to full and stick-slip breaks away above the sliding level with hysteresis") {
  auto v = core(PatternKind::Viscous);
  const auto f = run(v, ramp(0, 40.0, 0.1, 48000), 100.0, 0, 0);
  CHECK(level(f.back()) == Approx(0.4).margin(1e-4));
  auto s = core(PatternKind::StickSlip);
  // Speeds 0 -> 8 mm/s (past slipSpeed 5) -> 3 (between: still sliding) -> 1 (below stickSpeed 2).
  std::vector<float> x;
  double pos = 0;
  for (double speed : {0.0, 8.0, 3.0, 1.0})
    for (int i = 0; i < 4800; ++i) x.push_back(static_cast<float>(pos += speed / 48000));
  const auto g = run(s, x, 5.0, 2.0, 0);
  CHECK(g[4700] == Approx(kMaxN));   // at rest: stuck, breakaway force
  CHECK(g[9500] == Approx(kMinN));   // 8 mm/s: sliding
  CHECK(g[14300] == Approx(kMinN));  // 3 mm/s: still sliding (hysteresis)
  CHECK(g[19100] == Approx(kMaxN));  // 1 mm/s: stuck again
}

TEST_CASE("slope of a height signal: the rise over the frame's travel, free going down, held at rest") {
  auto c = core(PatternKind::Slope);
  // h = 0.25 * x: climbing at 0.25 per mm forward, descending backward; fullSlope 0.5.
  auto x = ramp(0.0, 10.0, 0.2, 48000);
  const auto back = ramp(2.0, -10.0, 0.1, 48000);
  x.insert(x.end(), back.begin(), back.end());
  std::vector<float> h(x.size());
  for (size_t i = 0; i < x.size(); ++i) h[i] = 0.25f * x[i];
  std::vector<float> f(x.size());
  for (size_t i = 0; i < x.size(); i += 64) {
    c.setParameters(0, 0.5, 0, x[i]);
    c.process(x.data() + i, 1, h.data() + i, 1, f.data() + i, 64);
  }
  CHECK(level(f[9000]) == Approx(0.5).margin(1e-4));
  CHECK(level(f[9600 + 2000]) == Approx(0.0).margin(1e-6));
}

TEST_CASE("bad inputs: NaN and inf positions hold, bad parameters keep the last good, outputs stay in range") {
  for (int kind = 0; kind < kPatternKinds; ++kind) {
    auto c = core(static_cast<PatternKind>(kind));
    std::vector<float> x = ramp(0, 30, 0.1, 48000);
    for (size_t i = 0; i < x.size(); i += 5) x[i] = (i / 5) % 3 == 0 ? kNaN : ((i / 5) % 3 == 1 ? kInf : -kInf);
    x[100] = 1e-40f;  // denormal
    std::vector<float> h(x.size(), kNaN);
    std::vector<float> f(x.size());
    const float bad[] = {kNaN, kInf, -kInf, 0.f, -3.f, 1e-38f, 1e38f};
    for (size_t i = 0; i < x.size(); i += 64) {
      const float p = bad[(i / 64) % 7];
      c.setParameters(i < 640 ? 1.0 : p, i < 640 ? 0.5 : p, i < 640 ? 0.1 : p, x[i]);
      c.process(x.data() + i, 1, h.data() + i, 1, f.data() + i, 64);
    }
    for (float v : f) {
      REQUIRE(std::isfinite(v));
      REQUIRE(v >= kMinN - 1e-6);
      REQUIRE(v <= kMaxN + 1e-6);
    }
  }
  const ForceRange r = usableForceRange(kNaN, -2);
  CHECK(r.loN == Approx(0.14));
  CHECK(r.hiN == 0.0);
}

TEST_CASE("extreme parameters and positions: tiny and huge periods, far from the origin, within range") {
  for (double period : {1e-9, 1e-3, 1e9}) {
    auto c = core(PatternKind::Grating);
    const auto f = run(c, ramp(1e6, 100.0, 0.05, 48000), period, 0.5, period * 10, 0);
    for (float v : f) REQUIRE((v >= kMinN - 1e-6 && v <= kMaxN + 1e-6));
    // A period far finer than the travel of a frame reads as its mean.
    if (period == 1e-9) CHECK(level(f.back()) == Approx(0.5).margin(1e-6));
  }
  // A period change where cycles overflow (1e38 mm over 1e-300 mm) leaves phase 0, not NaN for good.
  GratingPattern q;
  q.set(1e-300, 0.5, 0.0, 0.0);
  q.set(1.0, 0.5, 0.0, 1e38);
  CHECK(q.level(Travel{0.25, 0.25, 1, 0, 1e-3}, false) == 1.0);
  // A grating 1 km from the origin: 0.2 mm cells still exact (positions in double inside).
  GratingPattern p;
  p.set(0.2, 0.5, 0.0, 0.0);
  CHECK(p.level(Travel{1e6 + 0.05, 1e6 + 0.05, 1, 0, 1e-3}, false) == 1.0);
  CHECK(p.level(Travel{1e6 + 0.15, 1e6 + 0.15, 1, 0, 1e-3}, false) == 0.0);
}

TEST_CASE("far from the origin through the float input: exact at the float position, speed to its step") {
  // Positions reach the core as float: at 1e4 mm one step is 2^-10 mm (0.98 um), at 16 mm 2^-19.
  // Inside all is double, so a pattern is exact at the float position it got: the raw grating
  // (0.2 mm) at 1e4 mm is its definition there (to the force's float rounding, 1e-6 N). A speed
  // over a 1 ms frame is known to one step per ms: viscous at 40 mm/s (full at 100) may be off by
  // step / 1 ms / 100 mm/s: 9.8e-3 at 1e4 mm (measured 9.4e-3), 1.9e-5 at 16 mm.
  const auto far = ramp(1e4 + 0.013, 20.0, 0.1, 48000);
  auto raw = core(PatternKind::Grating, 48000, false);
  const auto f = run(raw, far, 0.2, 0.5, 0.02);
  for (size_t i = 0; i < far.size(); i += 3)
    REQUIRE(f[i] == Approx(kMinN + (kMaxN - kMinN) * gratingDef(frac(double(far[i]) / 0.2), 0.5, 0.1)).margin(1e-6));
  auto deviation = [](double x0) {
    auto v = core(PatternKind::Viscous);
    const auto g = run(v, ramp(x0, 40.0, 0.1, 48000), 100.0, 0, 0);
    double worst = 0;
    for (size_t i = 96; i < g.size(); ++i) worst = std::max(worst, std::fabs(level(g[i]) - 0.4));
    return worst;
  };
  const double farDeviation = deviation(1e4), nearDeviation = deviation(12.0);
  CHECK(farDeviation <= std::ldexp(1.0, -10) / 1e-3 / 100 + 1e-6);
  CHECK(farDeviation > 1e-3);  // the float path is what is tested: the step shows
  CHECK(nearDeviation <= std::ldexp(1.0, -19) / 1e-3 / 100 + 1e-6);
}

TEST_CASE("sample rates 44.1 to 192 kHz: the same grating against position, the frame exact to the sample") {
  const double period = 1.0, duty = 0.5, edge = 0.1;
  auto def = [&](double x) { return gratingDef(frac(x / period), duty, edge / period); };
  for (double sr : {44100.0, 48000.0, 88200.0, 96000.0, 192000.0}) {
    auto c = core(PatternKind::Grating, sr);
    // 0.5 mm/s over 1 mm: slow enough for the closed form (harmonic 1000 at the frames' 500 Hz,
    // past twice kSharp, 359 for an edge of 0.1 period).
    const auto x = ramp(0.0, 0.5, 0.45, sr);
    const auto f = run(c, x, period, duty, edge);
    const size_t n = static_cast<size_t>(std::round(sr * 1e-3));
    for (size_t i = n; i < x.size(); i += 211)
      REQUIRE(level(f[i]) == Approx(boxMean(def, x[i - n], x[i])).margin(2e-6));
  }
}
