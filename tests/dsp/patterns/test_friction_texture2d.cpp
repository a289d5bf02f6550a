// FrictionPattern's texture2D (dsp/patterns/TexturePattern in 2D) against its definition, written again
// here: 32 plane waves, per wave |f| in [lo, hi], angle and phase drawn by splitmix64 from the seed;
// level = clamp(1/2 + a * sum_k sin(2 pi f_k.p + phi_k)), a = 1 / (6 sqrt(16)). Moving, each wave
// is its mean over the frame's straight travel, faded on its own temporal frequency |f_k.v|.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <vector>

#include "PlanePaths.hpp"
#include "patterns/FrictionPatternCore.hpp"

using namespace kf::patterns;

namespace {

constexpr double kLoN = 0.14, kHiN = 0.5;
constexpr double kA = 1.0 / 24.0;  // 1 / (6 sqrt(32 / 2))

struct Wave {
  double fx, fy, phi;
};

std::vector<Wave> wavesOf(double lo, double hi, uint64_t seed) {
  uint64_t state = seed;
  auto next = [&state] {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
  };
  std::vector<Wave> w;
  for (int k = 0; k < 32; ++k) {
    const double m = lo + (hi - lo) * next(), angle = 2 * kPi * next(), phi = 2 * kPi * next();
    w.push_back({m * std::cos(angle), m * std::sin(angle), phi});
  }
  return w;
}

double wave(const Wave& w, double x, double y) { return std::sin(2 * kPi * (w.fx * x + w.fy * y) + w.phi); }

double definition(const std::vector<Wave>& ws, double x, double y) {
  double s = 0;
  for (const Wave& w : ws) s += wave(w, x, y);
  return std::clamp(0.5 + kA * s, 0.0, 1.0);
}

// The mean of a wave over the segment (x0, y0) -> (x1, y1) by Simpson's rule on 16 intervals
// (no closed form: at <= 0.1 cycles a segment its error is below 1e-9).
double segmentMean(const Wave& w, double x0, double y0, double x1, double y1) {
  const int n = 16;
  double s = 0;
  for (int i = 0; i <= n; ++i) {
    const double t = double(i) / n, weight = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    s += weight * wave(w, x0 + (x1 - x0) * t, y0 + (y1 - y0) * t);
  }
  return s / (3.0 * n);
}

using kf::testpaths::line;
using kf::testpaths::Path;

// Appends a straight segment from the path's end to (x, y) at speed mm/s, ending exactly there.
void goTo(Path& p, double x, double y, double speed, double rate) {
  const double x0 = p.x.back(), y0 = p.y.back();
  const int n = static_cast<int>(std::ceil(std::hypot(x - x0, y - y0) / speed * rate));
  for (int i = 1; i <= n; ++i) {
    p.x.push_back(static_cast<float>(i == n ? x : x0 + (x - x0) * i / n));
    p.y.push_back(static_cast<float>(i == n ? y : y0 + (y - y0) * i / n));
  }
}

Path rest(double x, double y, int samples) {
  Path p;
  p.x.assign(samples, static_cast<float>(x));
  p.y.assign(samples, static_cast<float>(y));
  return p;
}

// The core's levels over a path, parameters set per block of 64 (seedAt: the seed by sample).
template <class SeedAt>
std::vector<double> levelsSeeded(const Path& p, double rate, bool antialias, double lo, double hi, SeedAt seedAt) {
  FrictionPatternCore core(PatternKind::Texture2D, rate);
  core.setForceRange({kLoN, kHiN});
  core.setAntialias(antialias);
  std::vector<float> force(p.x.size());
  for (size_t i = 0; i < p.x.size(); i += 64) {
    const int n = static_cast<int>(std::min<size_t>(64, p.x.size() - i));
    core.setParameters(lo, hi, seedAt(i), p.x[i]);
    core.process(p.x.data() + i, 1, p.y.data() + i, 1, force.data() + i, n);
  }
  std::vector<double> out;
  for (float f : force) out.push_back((f - kLoN) / (kHiN - kLoN));
  return out;
}

std::vector<double> levels(const Path& p, double rate, bool antialias = true, double lo = 0.5, double hi = 3,
                           double seed = 7) {
  return levelsSeeded(p, rate, antialias, lo, hi, [seed](size_t) { return seed; });
}

// The force is a float: its level is exact to ~2^-24 * 0.5 N / 0.36 N = 8e-8; 1e-6 leaves room
// for the double rounding of 32 sines summed in another order.
constexpr double kTol = 1e-6;

// 1 ms frame means (48 samples at 48 kHz) of levels, as the device's force frames, in N.
std::vector<double> framesN(const std::vector<double>& levels) {
  std::vector<double> out;
  for (size_t i = 0; i + 48 <= levels.size(); i += 48) {
    double s = 0;
    for (size_t k = 0; k < 48; ++k) s += levels[i + k];
    out.push_back((kHiN - kLoN) * s / 48);
  }
  return out;
}

// The amplitude (N) at frequencyHz of 1 ms frames, by a DFT under a 4-term Blackman-Harris window
// (sidelobes below -92 dB), as test_friction_patterns.cpp's.
double amplitudeAt(const std::vector<double>& v, double frequencyHz) {
  const size_t n = v.size();
  std::complex<double> acc = 0;
  double wsum = 0, mean = 0;
  for (double a : v) mean += a / n;
  for (size_t i = 0; i < n; ++i) {
    const double p = 2 * kPi * i / n;
    const double w = 0.35875 - 0.48829 * std::cos(p) + 0.14128 * std::cos(2 * p) - 0.01168 * std::cos(3 * p);
    acc += (v[i] - mean) * w * std::polar(1.0, -2 * kPi * frequencyHz * i / 1000.0);
    wsum += w;
  }
  return 2 * std::abs(acc) / wsum;
}

}  // namespace

TEST_CASE("texture2D: the definition at rest and the mean of each wave along slow lines at angles, 44.1 to 192 kHz") {
  const auto ws = wavesOf(0.5, 3, 7);
  for (double x : {0.0, 0.37, -12.5})
    for (double y : {0.0, 2.9, -40.0})
      CHECK(TexturePattern::at2D(0.5, 3, 7, x, y) == Approx(definition(ws, x, y)).margin(1e-12));
  for (double rate : {44100.0, 48000.0, 96000.0, 192000.0}) {
    const size_t n = static_cast<size_t>(std::lround(rate * 1e-3));
    for (double angle : {0.0, kPi / 2, 0.5, 2.0, -2.5}) {
      // 25 mm/s: 0.025 mm a frame (<= 0.075 cycles of a wave); |f.v| <= 75 Hz, under the fade's
      // 250 Hz: every wave kept whole, the level the mean of each over the travel.
      Path p = rest(0.3, 0.7, 300);
      p.append(line(0.3, 0.7, angle, 25, 0.2, rate));
      const auto got = levels(p, rate);
      double worst = 0, lo = 1, hi = 0;
      for (size_t i = 0; i < 300; ++i) worst = std::max(worst, std::fabs(got[i] - definition(ws, 0.3f, 0.7f)));
      for (size_t i = 300 + n; i < got.size(); i += 7) {
        double s = 0;
        for (const Wave& w : ws) s += segmentMean(w, p.x[i - n], p.y[i - n], p.x[i], p.y[i]);
        worst = std::max(worst, std::fabs(got[i] - std::clamp(0.5 + kA * s, 0.0, 1.0)));
        lo = std::min(lo, got[i]), hi = std::max(hi, got[i]);
      }
      INFO("rate " << rate << " angle " << angle);
      CHECK(worst < kTol);
      CHECK(hi - lo > 0.2);  // 5 mm of texture: it varies
    }
  }
}

TEST_CASE("texture2D: a place feels the same at every visit, from any direction, whatever came between") {
  // Arrive at P = (2.1, -1.3) from the west, rest; go north-east, south, then arrive from the south
  // at another speed, rest; go north-west and arrive from there, rest. At rest the frame's travel
  // is 0: the definition at P, bit for bit the same at each visit.
  const double rate = 48000, px = 2.1, py = -1.3;
  Path p = line(px - 3, py, 0, 30, 0.1, rate);
  p.append(rest(px, py, 200));
  goTo(p, px + 3, py + 3, 40, rate);
  goTo(p, px, py - 4, 60, rate);
  goTo(p, px, py, 20, rate);
  p.append(rest(px, py, 200));
  goTo(p, px - 2, py + 2, 50, rate);
  goTo(p, px, py, 50, rate);
  p.append(rest(px, py, 200));
  const auto got = levels(p, rate);
  std::vector<double> atP;
  for (size_t i = 48; i < p.x.size(); ++i)
    if (p.x[i] == float(px) && p.y[i] == float(py) && p.x[i - 48] == p.x[i] && p.y[i - 48] == p.y[i])
      atP.push_back(got[i]);
  REQUIRE(atP.size() >= 3 * 152);  // three rests of 200 samples, less each one's first frame
  for (double v : atP) REQUIRE(v == atP.front());
  CHECK(atP.front() == Approx(definition(wavesOf(0.5, 3, 7), float(px), float(py))).margin(kTol));
}

TEST_CASE("texture2D: a new seed crossfades over 50 ms, and a second change during it waits, nothing steps") {
  // Seeds 1 -> 2 at 200 ms -> 3 at 220 ms (inside the fade) -> 4 at 240 ms, moving at 20 mm/s at
  // 30 degrees. Per sample the force may change by what the moving texture makes (the same run
  // with one seed: own) plus the fade's step, the range over 2400 samples. Replacing the texture
  // being faded in (no pending rule) steps by the fade weight times the difference (~0.04 N).
  const double rate = 48000;
  const Path p = line(0, 0, kPi / 6, 20, 0.5, rate);
  auto seeds = [](size_t i) { return i < 9600 ? 1.0 : (i < 10560 ? 2.0 : (i < 11520 ? 3.0 : 4.0)); };
  const auto changed = levelsSeeded(p, rate, true, 0.5, 3, seeds);
  auto worstStep = [](const std::vector<double>& l) {
    double worst = 0;
    for (size_t i = 49; i < l.size(); ++i) worst = std::max(worst, std::fabs(l[i] - l[i - 1]));
    return worst;
  };
  double own = 0;
  for (double seed : {1, 2, 3, 4}) own = std::max(own, worstStep(levels(p, rate, true, 0.5, 3, seed)));
  CHECK(worstStep(changed) <= own + 1.0 / 2400);
  // 1 -> 2 ends at 250 ms, then 2 -> 4 (the newest pending) ends at 300 ms: texture 4 alone, as
  // if it had been there from the start. Between, in the second fade, neither 2 nor 4 alone.
  const auto two = levels(p, rate, true, 0.5, 3, 2.0), four = levels(p, rate, true, 0.5, 3, 4.0);
  CHECK(changed[9600 + 2400 + 64] != two[9600 + 2400 + 64]);
  CHECK(changed[9600 + 2400 + 64] != four[9600 + 2400 + 64]);
  for (size_t i = 9600 + 2 * 2400 + 64; i < p.x.size(); ++i) REQUIRE(changed[i] == four[i]);
}

TEST_CASE("texture2D: each wave fades on its own temporal frequency, |f.v|: crests along the motion kept at 300 mm/s") {
  // |f| = 5 cycles/mm for every wave (lo = hi). Along x at 300 mm/s a wave at angle t to the
  // motion has 1500 |cos t| Hz: kept whole up to 250 Hz (|cos t| <= 1/6, crests within 9.6 degrees
  // of the motion), gone from 500 Hz (|cos t| >= 1/3). The level is the kept waves' frame means
  // alone, the fading ones by their gain; with the fade on |f| |v| instead, all would be gone.
  const double rate = 48000, speed = 300;
  const auto ws = wavesOf(5, 5, 1);
  for (bool alongX : {true, false}) {
    int along = 0, across = 0;
    for (const Wave& w : ws) {
      const double hz = speed * std::fabs(alongX ? w.fx : w.fy);
      along += hz <= 250, across += hz >= 500;
    }
    REQUIRE(along >= 3);  // this seed draws waves both ways along both axes
    REQUIRE(across >= 25);
    const Path p = line(0.4, -0.2, alongX ? 0 : kPi / 2, speed, 0.1, rate);
    const auto got = levels(p, rate, true, 5, 5, 1);
    double worst = 0, lo = 1, hi = 0;
    for (size_t i = 48; i < got.size(); i += 5) {
      double s = 0;
      for (const Wave& w : ws) {
        const double hz = speed * std::fabs(alongX ? w.fx : w.fy);
        const double gain = hz <= 250 ? 1 : (hz >= 500 ? 0 : 0.5 * (1 + std::cos(kPi * (hz - 250) / 250)));
        s += gain * segmentMean(w, p.x[i - 48], p.y[i - 48], p.x[i], p.y[i]);
      }
      worst = std::max(worst, std::fabs(got[i] - std::clamp(0.5 + kA * s, 0.0, 1.0)));
      lo = std::min(lo, got[i]), hi = std::max(hi, got[i]);
    }
    INFO((alongX ? "along x" : "along y"));
    CHECK(worst < kTol);
    INFO("swing " << lo << " .. " << hi);
    CHECK(hi - lo > 0.05);  // the waves along the motion are felt at 300 mm/s
  }
}

TEST_CASE(
    "texture2D: at 300 mm/s over a band of 5 cycles/mm no alias in the 1 ms frames, and at 5 mm/s the texture in "
    "full") {
  // Moving at v along 30 degrees, wave k has the temporal frequency |f_k.v| (Hz); a wave above the
  // frames' 500 Hz Nyquist frequency would fold to |F - 1000 m|. At each folded frequency (away
  // from DC and the kept waves' lines by 8 Hz: separable) the frames must hold nothing: left are
  // float rounding of the force (0.36 N * 2^-24 ~ 2e-8 N) and the window's leakage from the kept
  // lines (each <= 0.36 N * a = 0.015 N, -92 dB: 4e-7 N, ten of them 4e-6 N): stated 1e-5 N.
  // Measured 3.6e-8 N. Without anti-aliasing the same frequencies hold the folded waves: each
  // 0.36 N * a times the frame's box at its frequency (sinc(pi F 1 ms), 0.2 at 1300 Hz); measured
  // 9.1e-3 N at the largest, asserted > 3e-3 N: this test does see an alias.
  const double rate = 48000, speed = 300, angle = kPi / 6;
  const auto ws = wavesOf(5, 5, 3);
  const Path p = line(0.013, 0.021, angle, speed, 1.05, rate);
  std::vector<double> kept, folded;
  for (const Wave& w : ws) {
    const double hz = speed * std::fabs(w.fx * std::cos(angle) + w.fy * std::sin(angle));
    (hz < 500 ? kept : folded).push_back(hz < 500 ? hz : std::fabs(hz - 1000 * std::round(hz / 1000)));
  }
  auto separable = [&](double f) {
    if (f < 8) return false;
    for (double k : kept)
      if (std::fabs(f - k) < 8) return false;
    return true;
  };
  auto worstAlias = [&](bool antialias) {
    const auto fr = framesN(levels(p, rate, antialias, 5, 5, 3));
    const std::vector<double> second(fr.begin() + 50, fr.begin() + 1050);
    double worst = 0;
    int measured = 0;
    for (double f : folded)
      if (separable(f)) worst = std::max(worst, amplitudeAt(second, f)), ++measured;
    REQUIRE(measured >= 10);
    return worst;
  };
  const double on = worstAlias(true), off = worstAlias(false);
  INFO("alias with " << on << " N, without " << off << " N");
  CHECK(on < 1e-5);
  CHECK(off > 3e-3);
  // 5 mm/s: |f.v| <= 25 Hz, every wave kept; the frame's travel (0.005 mm, 0.025 cycles) shrinks a
  // wave by sinc(0.025 pi) = 1 - 1.03e-3 at most: the level is the definition at the travel's
  // midpoint but for 32 * a * 1.03e-3 = 1.4e-3 at most (measured 1.4e-4), and swings over most of
  // [0, 1] (measured 0.10 .. 0.79).
  const Path slow = line(0.013, 0.021, angle, 5, 0.5, rate);
  const auto got = levels(slow, rate, true, 5, 5, 3);
  double worst = 0, lo = 1, hi = 0;
  for (size_t i = 48; i < got.size(); ++i) {
    const double mx = 0.5 * (double(slow.x[i - 48]) + slow.x[i]), my = 0.5 * (double(slow.y[i - 48]) + slow.y[i]);
    worst = std::max(worst, std::fabs(got[i] - definition(ws, mx, my)));
    lo = std::min(lo, got[i]), hi = std::max(hi, got[i]);
  }
  INFO("5 mm/s: off the definition by " << worst << ", swing " << lo << " .. " << hi);
  CHECK(worst < 1.4e-3);
  CHECK(hi - lo > 0.5);
}

TEST_CASE("texture2D: NaN and inf positions hold, bad parameters keep the last good, huge coordinates") {
  const double rate = 48000;
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN(), kInf = std::numeric_limits<float>::infinity();
  const Path p = line(0.3, 0.7, 0.5, 60, 0.1, rate);
  const auto clean = levels(p, rate);
  Path bad = p, holding = p;
  for (size_t i = 2000; i < 2010; ++i) {
    bad.x[i] = kNaN, bad.y[i] = (i % 2 ? kInf : -kInf);
    holding.x[i] = p.x[1999], holding.y[i] = p.y[1999];
  }
  const auto held = levels(bad, rate), want = levels(holding, rate);
  for (size_t i = 0; i < p.x.size(); ++i) REQUIRE(held[i] == want[i]);
  CHECK(held[2005] != clean[2005]);  // the hold is what is tested
  // Bad band and seed from the start: band 0.5..3 cycles/mm and seed 0 (sclang's defaults), here at rest.
  const Path still = rest(1.7, -0.4, 100);
  const auto defaults = levels(still, rate, true, std::nan(""), -1, HUGE_VAL);
  CHECK(defaults.back() == Approx(definition(wavesOf(0.5, 3, 0), 1.7f, -0.4f)).margin(kTol));
  // Far from the origin at rest: the definition at the float position. 2 pi * 3 cycles/mm * 3e8 mm
  // is 5.7e9 rad, whose double rounding (~5e-7 rad, each implementation its own) moves 32 waves by
  // 32 * a * 5e-7 = 7e-7: the tolerance is the float force's 1e-6 plus that.
  for (double x : {1e6, -7.5e7, 3e8}) {
    const auto far = levels(rest(x, -0.5 * x, 100), rate);
    CHECK(far.back() == Approx(definition(wavesOf(0.5, 3, 7), float(x), float(-0.5 * x))).margin(2e-6));
  }
  // Beyond: finite and within range, at rest and moving near float's largest (frames 2e36 mm long).
  Path extreme = rest(3e38, -3e38, 100);
  extreme.append(line(-3e38, 3e38, 1.0, 1e39, 0.01, rate));
  for (double v : levels(extreme, rate)) REQUIRE((v >= 0.0 && v <= 1.0));
}
