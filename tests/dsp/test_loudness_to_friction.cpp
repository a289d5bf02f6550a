// LoudnessToFriction against equations (1) and (2) recomputed in double, on the hard cases.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <vector>

#include "CorePathScope.hpp"
#include "LoudnessToFriction.hpp"

using kf::FrictionMapping;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Owns the history a plugin would RTAlloc.
struct Core {
  std::vector<float> history;
  kf::LoudnessToFriction core;
  explicit Core(int maxWindow) : history(maxWindow), core(history.data(), maxWindow) {}
};

// Equation (2) as the paper writes it, in double and written here, not taken from dsp/: the level
// L = 20 log10(mean / ref) dB places the force linearly between loForce at loDb and hiForce at
// hiDb, held at the ends (silence is L = -inf). Reversed bounds hold the same way (the fraction
// is clamped to [0, 1]); equal bounds are a threshold.
double paperEquation2(double meanAbs, const FrictionMapping& m) {
  const double levelDb = meanAbs > 0.0 ? 20.0 * std::log10(meanAbs / m.ref) : -HUGE_VAL;
  if (m.hiDb == m.loDb) return levelDb >= m.hiDb ? m.hiForceN : m.loForceN;
  const double fraction = std::min(1.0, std::max(0.0, (levelDb - m.loDb) / (m.hiDb - m.loDb)));
  return m.loForceN + fraction * (m.hiForceN - m.loForceN);
}

// Equations (1) and (2) straight from the paper, in double, with zeros before the start.
struct Reference {
  std::deque<double> window;
  int n;
  FrictionMapping mapping;
  explicit Reference(int windowSamples, FrictionMapping m = {})
      : window(windowSamples, 0.0), n(windowSamples), mapping(m) {}
  double operator()(float a) {
    double x = std::isfinite(a) ? std::fabs(double(a)) : (std::isnan(a) ? 0.0 : 1e30);
    window.push_back(x);
    window.pop_front();
    double sum = 0;
    for (double v : window) sum += v;
    return paperEquation2(sum / n, mapping);
  }
};

// Deterministic white noise in [-1, 1).
struct Noise {
  uint64_t state = 0x9E3779B97F4A7C15ull;
  float operator()() {
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return static_cast<float>((state >> 40) * (1.0 / 8388608.0) - 1.0);
  }
};

std::vector<float> runCore(Core& c, const std::vector<float>& in) {
  std::vector<float> out(in.size());
  c.core.process(in.data(), out.data(), static_cast<int>(in.size()));
  return out;
}

}  // namespace

TEST_CASE("reference mapping: the paper's end points and the full-scale sine") {
  FrictionMapping m;
  CHECK(kf::frictionFromMeanAbs(0.0, m) == 0.14);
  CHECK(kf::frictionFromMeanAbs(1.0, m) == 0.5);
  CHECK(kf::frictionFromMeanAbs(std::pow(10.0, -1.5), m) == Approx(0.14));
  CHECK(kf::frictionFromMeanAbs(2.0 / kPi, m) == Approx(0.14 + 0.36 * (1 + 20 * std::log10(2 / kPi) / 30)));
  CHECK(kf::frictionFromMeanAbs(2.0 / kPi, m) == Approx(0.4530).margin(1e-4));
  // The tests' own equation (2) gives the paper's numbers too.
  CHECK(paperEquation2(0.0, m) == 0.14);
  CHECK(paperEquation2(1.0, m) == 0.5);
  CHECK(paperEquation2(2.0 / kPi, m) == Approx(0.4530).margin(1e-4));
}

TEST_CASE("window length is round(sr x window), clamped to [1, max]") {
  CHECK(kf::windowSamples(192000, 0.001, 1000) == 192);
  CHECK(kf::windowSamples(44100, 0.001, 1000) == 44);
  CHECK(kf::windowSamples(48000, 0.001, 1000) == 48);
  CHECK(kf::windowSamples(96000, 0.001, 1000) == 96);
  CHECK(kf::windowSamples(48000, 1.0, 1000) == 1000);
  CHECK(kf::windowSamples(48000, 0.0, 1000) == 1);
  CHECK(kf::windowSamples(48000, -1.0, 1000) == 1);
  CHECK(kf::windowSamples(48000, std::numeric_limits<double>::quiet_NaN(), 1000) == 1);
  CHECK(kf::windowSamples(48000, std::numeric_limits<double>::infinity(), 1000) == 1000);
}

TEST_CASE("silence gives exactly loForce, from the first sample on") {
  EACH_CORE_PATH();
  Core c(192);
  c.core.setWindowSamples(192);
  auto out = runCore(c, std::vector<float>(5000, 0.f));
  for (float f : out) REQUIRE(f == 0.14f);
}

TEST_CASE("a full-scale square gives exactly hiForce once the window is full") {
  EACH_CORE_PATH();
  Core c(192);
  c.core.setWindowSamples(192);
  std::vector<float> in(4000);
  for (size_t i = 0; i < in.size(); ++i) in[i] = (i / 96) % 2 ? -1.f : 1.f;
  auto out = runCore(c, in);
  for (size_t i = 191; i < out.size(); ++i) REQUIRE(out[i] == 0.5f);
}

TEST_CASE("a full-scale sine gives 0.4530 N") {
  EACH_CORE_PATH();
  // 1 kHz at 192 kHz: the 1 ms window holds whole periods, so the mean of |sin| is 2/pi up to
  // the sampling of the period.
  Core c(192);
  c.core.setWindowSamples(192);
  std::vector<float> in(19200);
  for (size_t i = 0; i < in.size(); ++i) in[i] = static_cast<float>(std::sin(2 * kPi * 1000 * i / 192000.0));
  auto out = runCore(c, in);
  const double want = 0.14 + 0.36 * (1 + 20 * std::log10(2 / kPi) / 30);
  for (size_t i = 192; i < out.size(); ++i) REQUIRE(out[i] == Approx(want).margin(2e-4));
}

TEST_CASE("per-sample agreement with equations (1) and (2) at 44.1 to 192 kHz") {
  EACH_CORE_PATH();
  for (double sr : {44100.0, 48000.0, 96000.0, 192000.0}) {
    const int n = kf::windowSamples(sr, 0.001, 400);
    Core c(400);
    c.core.setWindowSamples(n);
    Reference ref(n);
    Noise noise;
    std::vector<float> in(3000);
    // Noise whose level sweeps through the whole clip range and beyond.
    for (size_t i = 0; i < in.size(); ++i)
      in[i] = noise() * static_cast<float>(std::pow(10.0, -2.5 + 3.0 * i / in.size()));
    auto out = runCore(c, in);
    for (size_t i = 0; i < in.size(); ++i) REQUIRE(out[i] == Approx(ref(in[i])).margin(1e-6));
  }
}

TEST_CASE("NaN and Inf input never reach the output") {
  EACH_CORE_PATH();
  Core c(48);
  c.core.setWindowSamples(48);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::vector<float> in(1000, 0.5f);
  in[100] = nan, in[200] = inf, in[300] = -inf, in[301] = nan;
  auto out = runCore(c, in);
  Reference ref(48);
  for (size_t i = 0; i < in.size(); ++i) {
    REQUIRE(std::isfinite(out[i]));
    REQUIRE(out[i] == Approx(ref(in[i])).margin(1e-6));
  }
  CHECK(out[210] == 0.5f);  // Inf is as loud as it gets
  // ...and the running sum recovers once the Inf has left the window.
  CHECK(out[999] == Approx(paperEquation2(0.5, FrictionMapping{})).margin(1e-6));
}

TEST_CASE("denormals and tiny levels read as loForce") {
  EACH_CORE_PATH();
  Core c(192);
  c.core.setWindowSamples(192);
  std::vector<float> in(2000);
  for (size_t i = 0; i < in.size(); ++i)
    in[i] = (i % 2 ? 1 : -1) * std::numeric_limits<float>::denorm_min() * (1 + i % 7);
  for (float f : runCore(c, in)) REQUIRE(f == 0.14f);
}

TEST_CASE("full scale and above clip at hiForce") {
  EACH_CORE_PATH();
  Core c(48);
  c.core.setWindowSamples(48);
  for (float level : {1.f, 10.f, 1e6f, 3e38f}) {
    auto out = runCore(c, std::vector<float>(200, level));
    REQUIRE(out.back() == 0.5f);
  }
}

TEST_CASE("extreme and reversed mappings") {
  EACH_CORE_PATH();
  SECTION("reversed dB bounds: louder means less friction") {
    FrictionMapping m{0.0, -30.0, 0.14, 0.5, 1.0};
    Core c(48);
    c.core.setWindowSamples(48);
    c.core.setMapping(m);
    CHECK(runCore(c, std::vector<float>(100, 1.f)).back() == Approx(0.14f));
    CHECK(runCore(c, std::vector<float>(100, 0.f)).back() == Approx(0.5f));
  }
  SECTION("loDb == hiDb is a threshold") {
    FrictionMapping m{-6.0, -6.0, 0.2, 1.0, 1.0};
    Core c(8);
    c.core.setWindowSamples(8);
    c.core.setMapping(m);
    CHECK(runCore(c, std::vector<float>(16, 0.6f)).back() == 1.0f);
    CHECK(runCore(c, std::vector<float>(16, 0.4f)).back() == 0.2f);
  }
  SECTION("bad ref and non-finite bounds fall back to the paper's values") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Core c(8);
    c.core.setWindowSamples(8);
    c.core.setMapping(FrictionMapping{nan, nan, nan, nan, -1.0});
    CHECK(runCore(c, std::vector<float>(16, 1.f)).back() == 0.5f);
    CHECK(runCore(c, std::vector<float>(16, 0.f)).back() == 0.14f);
  }
  SECTION("a negative force is 0 N: friction never pushes") {
    Core c(8);
    c.core.setWindowSamples(8);
    c.core.setMapping(FrictionMapping{-30.0, 0.0, -1.0, -0.5, 1.0});
    CHECK(runCore(c, std::vector<float>(16, 1.f)).back() == 0.f);
    CHECK(runCore(c, std::vector<float>(16, 0.f)).back() == 0.f);
  }
  SECTION("usableMapping says what setMapping uses") {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    const FrictionMapping paper;
    const FrictionMapping bad = kf::usableMapping(FrictionMapping{nan, -inf, inf, -2.0, 0.0});
    CHECK(bad.loDb == paper.loDb);
    CHECK(bad.hiDb == paper.hiDb);
    CHECK(bad.loForceN == paper.loForceN);
    CHECK(bad.hiForceN == 0.0);
    CHECK(bad.ref == paper.ref);
    // Reversed, threshold and huge values are kept as they are.
    const FrictionMapping kept = kf::usableMapping(FrictionMapping{1e30, -1e30, 3e38, 0.0, 1e-30});
    CHECK(kept.loDb == 1e30);
    CHECK(kept.hiDb == -1e30);
    CHECK(kept.loForceN == 3e38);
    CHECK(kept.hiForceN == 0.0);
    CHECK(kept.ref == 1e-30);
  }
  SECTION("a tiny ref moves 0 dB down") {
    FrictionMapping m;
    m.ref = 1e-6;
    Core c(8);
    c.core.setWindowSamples(8);
    c.core.setMapping(m);
    CHECK(runCore(c, std::vector<float>(16, 1e-6f)).back() == Approx(0.5f));
  }
}

// Every output lies within [loForce, hiForce]: the fast logarithm's error and rounding are
// clamped away at both ends, for rising, reversed and far-off mappings. The last two went past
// a bound by about 1e-7 N without the clamp (found by a random search near the bounds).
TEST_CASE("the force never leaves [loForce, hiForce]") {
  EACH_CORE_PATH();
  const FrictionMapping mappings[] = {FrictionMapping{},
                                      {0.0, -30.0, 0.14, 0.5, 1.0},
                                      {-30.0, 0.0, 0.5, 0.14, 1.0},
                                      {-1e30, 1e30, 0.14, 1.4, 1.0},
                                      {-3.0, -2.0, 0.0, 1000.0, 1.0},
                                      {-18.776998966811725, -3.0221598034845396, 0.516272664, 0.843547344, 1.0},
                                      {-7.1003481379589743, 1.9105385349107724, 0.103913911, 0.445142716, 1.0}};
  for (const FrictionMapping& m : mappings) {
    Core c(1);
    c.core.setWindowSamples(1);  // the output is the mapping of |a| itself
    c.core.setMapping(m);
    // Levels across and beyond the clip range, and the 64 floats on each side of each bound.
    std::vector<float> in;
    for (int i = 0; i <= 4096; ++i) in.push_back(static_cast<float>(std::pow(10.0, (-80.0 + 100.0 * i / 4096) / 20.0)));
    for (double db : {m.loDb, m.hiDb}) {
      const float x = static_cast<float>(m.ref * std::pow(10.0, db / 20.0));
      float below = x, above = x;
      for (int k = 0; k < 64; ++k) {
        in.push_back(below = std::nextafter(below, 0.f));
        in.push_back(above = std::nextafter(above, 1e30f));
      }
    }
    const std::vector<float> out = runCore(c, in);
    const float lo = static_cast<float>(std::min(m.loForceN, m.hiForceN));
    const float hi = static_cast<float>(std::max(m.loForceN, m.hiForceN));
    for (float f : out)
      if (!(f >= lo && f <= hi)) FAIL_CHECK("force " << f << " N outside [" << lo << ", " << hi << "]");
  }
}

TEST_CASE("the window can change while running, up to the maximum") {
  EACH_CORE_PATH();
  Core c(500);
  c.core.setWindowSamples(48);
  Noise noise;
  std::vector<float> all;
  std::vector<float> out;
  int n = 48;
  for (int block = 0; block < 60; ++block) {
    if (block % 10 == 5) n = (n * 7) % 499 + 1;
    if (block == 40) n = 10000;  // beyond the maximum: clamps
    c.core.setWindowSamples(n);
    std::vector<float> in(64);
    for (float& x : in) x = noise() * 0.3f;
    auto o = runCore(c, in);
    const int used = c.core.windowSamples();
    REQUIRE(used == std::min(n, 500));
    for (int i = 0; i < 64; ++i) {
      all.push_back(in[i]);
      double sum = 0;
      for (int k = 0; k < used && k < static_cast<int>(all.size()); ++k) sum += std::fabs(all[all.size() - 1 - k]);
      REQUIRE(o[i] == Approx(paperEquation2(sum / used, FrictionMapping{})).margin(1e-6));
    }
  }
}

namespace {

// White noise at about -18 dB (inside the clip range) through a 192-sample window for `total`
// samples; every `checkEvery` samples (a multiple of the block) the last output and the running
// mean are checked against the last n samples recomputed in double. Returns the worst error.
double driftWorstN(int64_t total, int64_t checkEvery) {
  const int n = 192;
  Core c(n);
  c.core.setWindowSamples(n);
  Noise noise;
  constexpr int kBlock = 4096;
  std::vector<float> in(kBlock), out(kBlock);
  int64_t done = 0;
  double worstN = 0.0;
  while (done < total) {
    for (float& x : in) x = noise() * 0.25f;
    c.core.process(in.data(), out.data(), kBlock);
    done += kBlock;
    if (done % checkEvery == 0 || done >= total) {
      double sum = 0;
      for (int k = 0; k < n; ++k) sum += std::fabs(double(in[kBlock - 1 - k]));
      const double want = paperEquation2(sum / n, FrictionMapping{});
      worstN = std::max(worstN, std::fabs(out[kBlock - 1] - want));
      REQUIRE(out[kBlock - 1] == Approx(want).margin(1e-6));
      REQUIRE(c.core.meanAbs() == Approx(sum / n).epsilon(1e-12));
    }
  }
  return worstN;
}

}  // namespace

// On the path this processor dispatches to (the one a server runs); the other path gets the
// shorter run below, as the loops that carry the sum are the same from one lap to the next.
TEST_CASE("no drift: 10^9 samples of white noise against a double recomputation", "[long]") {
  INFO("core path " << kf::corePathName(kf::corePath()));
  const double worstN = driftWorstN(1000000000, 4096 * 24414);  // about every 10^8 samples
  INFO("worst |error| " << worstN << " N");
  CHECK(worstN < 1e-6);
}

TEST_CASE("no drift on the portable path: 10^7 samples against a double recomputation") {
  PathScope pathScope(kf::CorePath::portable);
  const double worstN = driftWorstN(10000000, 4096 * 244);  // about every 10^6 samples
  INFO("worst |error| " << worstN << " N");
  CHECK(worstN < 1e-6);
}

// The fast logarithm of equation (2): where it is used, its worst error over the whole clip
// range is within 1e-6 N; where a bound says it could not be, the exact path is taken.
TEST_CASE("fast logarithm: worst error over the clip range, and when it is not used") {
  EACH_CORE_PATH();
  SECTION("the paper's mapping uses it, within 1e-6 N at every level across the clip range") {
    Core c(1);
    c.core.setWindowSamples(1);  // the output is the mapping of |a| itself
    REQUIRE(c.core.usesFastLog());
    const int count = 1 << 20;
    std::vector<float> in(count), out(count);
    // Log-spaced levels from -31 to +1 dB, plus the exact bounds and their float neighbours.
    for (int i = 0; i < count; ++i) in[i] = static_cast<float>(std::pow(10.0, (-31.0 + 32.0 * i / (count - 1)) / 20.0));
    const float lo = static_cast<float>(std::pow(10.0, -1.5));
    for (float x : {lo, std::nextafter(lo, 0.f), std::nextafter(lo, 1.f), 1.f, std::nextafter(1.f, 0.f),
                    std::nextafter(1.f, 2.f)})
      in.push_back(x), out.push_back(0.f);
    c.core.process(in.data(), out.data(), static_cast<int>(in.size()));
    double worst = 0;
    for (size_t i = 0; i < in.size(); ++i)
      worst = std::max(worst, std::fabs(out[i] - paperEquation2(in[i], FrictionMapping{})));
    INFO("worst |error| " << worst << " N");
    CHECK(worst <= 1e-6);
  }
  SECTION("a steep mapping takes the exact path and stays within 1e-6 N") {
    const FrictionMapping steep{-3.0, -2.0, 0.0, 1000.0, 1.0};  // 1000 N per dB
    Core c(1);
    c.core.setWindowSamples(1);
    c.core.setMapping(steep);
    CHECK_FALSE(c.core.usesFastLog());
    std::vector<float> in(4096), out(4096);
    for (size_t i = 0; i < in.size(); ++i) in[i] = static_cast<float>(std::pow(10.0, (-3.1 + 1.2 * i / 4095) / 20.0));
    c.core.process(in.data(), out.data(), 4096);
    for (size_t i = 0; i < in.size(); ++i) {
      const double want = paperEquation2(in[i], steep);
      REQUIRE(out[i] == Approx(want).margin(std::max(1e-6, want * 1e-7)));  // float output
    }
  }
  SECTION("a threshold (loDb == hiDb) takes the exact path") {
    Core c(8);
    c.core.setMapping(FrictionMapping{-6.0, -6.0, 0.2, 1.0, 1.0});
    CHECK_FALSE(c.core.usesFastLog());
  }
}

TEST_CASE("the code path is chosen from the processor and KF_CORE_PATH") {
  using kf::CorePath;
  CHECK(kf::chooseCorePath(true, nullptr) == CorePath::avx2);
  CHECK(kf::chooseCorePath(true, "") == CorePath::avx2);
  CHECK(kf::chooseCorePath(true, "avx2") == CorePath::avx2);
  CHECK(kf::chooseCorePath(true, "portable") == CorePath::portable);
  // Without AVX2/FMA the portable path runs, whatever is asked for.
  CHECK(kf::chooseCorePath(false, nullptr) == CorePath::portable);
  CHECK(kf::chooseCorePath(false, "avx2") == CorePath::portable);
  CHECK(kf::chooseCorePath(false, "portable") == CorePath::portable);
  {
    PathScope scope(CorePath::avx2);
    CHECK(scope.used == (kf::cpuHasAvx2Fma() ? CorePath::avx2 : CorePath::portable));
    CHECK(kf::corePath() == scope.used);
  }
  {
    PathScope scope(CorePath::portable);
    CHECK(kf::corePath() == CorePath::portable);
  }
}

// setCorePath really changes the code that runs: the AVX2 path sums eight at a time and uses
// FMA, so somewhere in the last bits its forces differ from the portable ones; the two agree
// within the float output's rounding (the test above compares block sizes with the same margin).
TEST_CASE("the two code paths are different code and agree") {
  if (!kf::cpuHasAvx2Fma()) return;  // one path only on this processor
  Noise noise;
  std::vector<float> in(20000);
  for (size_t i = 0; i < in.size(); ++i)
    in[i] = noise() * static_cast<float>(std::pow(10.0, -2.5 + 3.0 * i / in.size()));
  std::vector<float> byPath[2];
  for (kf::CorePath path : {kf::CorePath::portable, kf::CorePath::avx2}) {
    PathScope scope(path);
    Core c(48);
    c.core.setWindowSamples(48);
    byPath[static_cast<int>(path)] = runCore(c, in);
  }
  int differ = 0;
  for (size_t i = 0; i < in.size(); ++i) {
    REQUIRE(byPath[1][i] == Approx(byPath[0][i]).margin(2e-7));
    differ += byPath[1][i] != byPath[0][i];
  }
  INFO(differ << " of " << in.size() << " forces differ");
  CHECK(differ > 0);
}

TEST_CASE("block sizes, in-place processing and tiny rings give the same forces") {
  EACH_CORE_PATH();
  Noise noise;
  std::vector<float> in(5000);
  for (size_t i = 0; i < in.size(); ++i)
    in[i] = noise() * static_cast<float>(std::pow(10.0, -2.5 + 3.0 * i / in.size()));
  for (int maxWindow : {1, 3, 48, 200, 1000}) {
    const int n = std::max(1, maxWindow * 2 / 3);
    std::vector<float> whole;
    {
      Core c(maxWindow);
      c.core.setWindowSamples(n);
      whole = runCore(c, in);
      Reference ref(n);
      for (size_t i = 0; i < in.size(); ++i) REQUIRE(whole[i] == Approx(ref(in[i])).margin(1e-6));
    }
    for (int block : {1, 7, 64, 127, 128, 129, 1024}) {
      Core c(maxWindow);
      c.core.setWindowSamples(n);
      std::vector<float> buf(in);  // processed in place
      for (size_t done = 0; done < buf.size(); done += block) {
        const int len = static_cast<int>(std::min<size_t>(block, buf.size() - done));
        c.core.process(buf.data() + done, buf.data() + done, len);
      }
      for (size_t i = 0; i < in.size(); ++i) REQUIRE(buf[i] == Approx(whole[i]).margin(2e-7));
    }
  }
}
