// The "faster logarithm" choice of LoudnessToFriction, measured: for each way of taking the
// logarithm in equation (2), the time per sample and the worst force error (N) over the clip
// range, (a) for the mapping alone over an array of mean amplitudes and (b) inside a copy of
// the core's per-sample loop (running sum + mapping) fed an input whose mean stays inside the
// clip range, so that every sample takes a logarithm (the worst case). The real
// kf::LoudnessToFriction::process is timed on the same input for comparison.
// Plain executable, no test framework: prints one line per variant, and a machine-readable
// "RESULT" line each that bench/run.py parses.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "CorePath.hpp"
#include "LoudnessToFriction.hpp"

namespace {

// M_PI is POSIX's, not C++17's: MinGW has none (a user's default Windows build stopped here).
constexpr double kPi = 3.14159265358979323846;

// The paper's mapping: [-30, 0] dB -> [0.14, 0.5] N.
constexpr double kLoDb = kf::paper::mapping::loDb, kHiDb = kf::paper::mapping::hiDb;
constexpr double kLoForceN = kf::paper::mapping::loForceN, kHiForceN = kf::paper::mapping::hiForceN;
constexpr double kForcePerDb = (kHiForceN - kLoForceN) / (kHiDb - kLoDb);
constexpr double kForceOffset = kLoForceN - kLoDb * kForcePerDb;
const double kLoAbs = std::pow(10.0, kLoDb / 20.0), kHiAbs = 1.0;

// log2 of a positive normal float: exponent from the bits, mantissa m folded into
// [sqrt(1/2), sqrt(2)) so the polynomial or series only has to cover |m - 1| <= 0.415.
inline void splitLog2(float x, float& m, float& e) {
  uint32_t bits;
  std::memcpy(&bits, &x, 4);
  int ex = static_cast<int>((bits >> 23) & 0xff) - 127;
  bits = (bits & 0x007fffffu) | 0x3f800000u;
  std::memcpy(&m, &bits, 4);
  if (m > 1.41421356f) {
    m *= 0.5f;
    ++ex;
  }
  e = static_cast<float>(ex);
}

// ln m = 2 atanh(s), s = (m - 1) / (m + 1), |s| <= 0.1716: odd series, `Terms` terms.
template <int Terms>
inline float fastLog2Atanh(float x) {
  float m, e;
  splitLog2(x, m, e);
  const float s = (m - 1.f) / (m + 1.f), s2 = s * s;
  float p;
  if constexpr (Terms == 3)
    p = 1.f + s2 * (1.f / 3.f + s2 * (1.f / 5.f));
  else
    p = 1.f + s2 * (1.f / 3.f + s2 * (1.f / 5.f + s2 * (1.f / 7.f)));
  return e + 2.f * s * p * 1.44269504f;
}

// log2(1 + t) = t P(t), P fitted (least squares at Chebyshev nodes) on t in [-0.293, 0.415].
template <int Degree>
inline float fastLog2Poly(float x) {
  float m, e;
  splitLog2(x, m, e);
  const float t = m - 1.f;
  float p;
  if constexpr (Degree == 5)
    p = 1.44270180f +
        t * (-0.72120847f + t * (0.47979388f + t * (-0.36641326f + t * (0.31840712f + t * -0.20685812f))));
  else
    p = 1.44269643f +
        t * (-0.72136404f +
             t * (0.48062915f + t * (-0.35935065f + t * (0.29563360f + t * (-0.26950627f + t * 0.17212873f)))));
  return e + t * p;
}

// Each variant: force (N) of a mean amplitude inside (loAbs, hiAbs), as mapMeanAbs computes it.
constexpr double kLog10Of2 = 0.30102999566398120;
constexpr double kLog10OfE = 0.43429448190325182;
constexpr float kForcePerLog2F = float(20.0 * kLog10Of2 * kForcePerDb);
constexpr float kForceOffsetF = float(kForceOffset);

inline float forceLog10(double a) { return float(20.0 * std::log10(a) * kForcePerDb + kForceOffset); }
inline float forceLn(double a) { return float(20.0 * kLog10OfE * kForcePerDb * std::log(a) + kForceOffset); }
inline float forceLog2(double a) { return float(20.0 * kLog10Of2 * kForcePerDb * std::log2(a) + kForceOffset); }
inline float forceLog10f(double a) { return 20.f * log10f(float(a)) * float(kForcePerDb) + kForceOffsetF; }
inline float forceLog2f(double a) { return log2f(float(a)) * kForcePerLog2F + kForceOffsetF; }
inline float forceAtanh3(double a) { return fastLog2Atanh<3>(float(a)) * kForcePerLog2F + kForceOffsetF; }
inline float forceAtanh4(double a) { return fastLog2Atanh<4>(float(a)) * kForcePerLog2F + kForceOffsetF; }
inline float forcePoly5(double a) { return fastLog2Poly<5>(float(a)) * kForcePerLog2F + kForceOffsetF; }
inline float forcePoly6(double a) { return fastLog2Poly<6>(float(a)) * kForcePerLog2F + kForceOffsetF; }

volatile float gSink;

template <typename F>
double bestSecondsOf(int repeats, F&& f) {
  double best = 1e30;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

// A copy of LoudnessToFriction::process with the mapping swapped, for (b).
template <float (*Force)(double)>
struct CoreCopy {
  std::vector<float> history;
  int capacity, n, w = 0;
  double sum = 0.0;
  CoreCopy(int cap, int win) : history(cap, 0.f), capacity(cap), n(win) {}
  void resum() {
    double s = 0.0;
    int k = w;
    for (int i = 0; i < n; ++i) {
      k = (k == 0 ? capacity : k) - 1;
      s += history[k];
    }
    sum = s;
  }
  void process(const float* in, float* out, int count) {
    const double invN = 1.0 / n;
    const float maxAbs = 1e30f;
    for (int i = 0; i < count; ++i) {
      float x = std::fabs(in[i]);
      if (!(x <= maxAbs)) x = std::isnan(x) ? 0.f : maxAbs;
      int oldest = w - n;
      if (oldest < 0) oldest += capacity;
      sum += double(x) - history[oldest];
      history[w] = x;
      if (++w == capacity) {
        w = 0;
        resum();
      }
      const double mean = std::max(sum, 0.0) * invN;
      out[i] = mean >= kHiAbs ? float(kHiForceN) : mean <= kLoAbs ? float(kLoForceN) : Force(mean);
    }
  }
};

}  // namespace

int main() {
  // (a) the mapping alone. Error: a dense log-spaced sweep of the clip range against the
  // double reference kf::frictionFromMeanAbs, with the same float rounding of the output.
  const int sweep = 1 << 22;
  std::vector<double> sweepAbs(sweep);
  for (int i = 0; i < sweep; ++i) sweepAbs[i] = kLoAbs * std::pow(kHiAbs / kLoAbs, (i + 0.5) / sweep);
  const kf::FrictionMapping paper;
  std::vector<double> reference(sweep);
  for (int i = 0; i < sweep; ++i) reference[i] = kf::frictionFromMeanAbs(sweepAbs[i], paper);

  // Timing: a 4096-value block (in L1) of random means inside the range, many passes.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int block = 4096, passes = 2000;
  std::vector<double> blockAbs(block);
  for (auto& a : blockAbs) a = kLoAbs * std::pow(kHiAbs / kLoAbs, u(rng));
  std::vector<float> blockOut(block);

  // (b) input for the core loop: 48 kHz, 1 ms window (n = 48), noise whose mean |a| wanders
  // inside -27..-3 dB, so every sample is inside the clip range.
  const int capacity = 2400, window = 48, samples = 1 << 20;
  std::vector<float> input(samples);
  std::normal_distribution<float> g(0.f, 1.f);
  for (int i = 0; i < samples; ++i) {
    const double db = -15.0 + 12.0 * std::sin(2.0 * kPi * i / 48000.0 * 0.7);
    input[i] = float(std::pow(10.0, db / 20.0) * 1.2533 * g(rng));  // E|N(0,1)| = 0.798
  }
  std::vector<float> coreOut(samples);

  std::printf("%-38s %12s %12s %14s %14s\n", "log variant", "map ns/value", "core ns/samp", "worst err N", "rms err N");
  const int coreRepeats = 15;
  auto coreTime = [&](auto& core) {
    return bestSecondsOf(coreRepeats,
                         [&] {
                           for (int i = 0; i < samples; i += 64) core.process(input.data() + i, coreOut.data() + i, 64);
                         }) /
           samples * 1e9;
  };
  auto run = [&](const char* name, auto force, auto core) {
    double worst = 0.0, sq = 0.0;
    for (int i = 0; i < sweep; ++i) {
      const double err = std::fabs(double(force(sweepAbs[i])) - reference[i]);
      worst = std::max(worst, err);
      sq += err * err;
    }
    const double rms = std::sqrt(sq / sweep);
    const double mapNs = bestSecondsOf(9,
                                       [&] {
                                         for (int p = 0; p < passes; ++p) {
                                           for (int i = 0; i < block; ++i) blockOut[i] = force(blockAbs[i]);
                                           gSink = blockOut[p % block];
                                         }
                                       }) /
                         (double(block) * passes) * 1e9;
    const double coreNs = coreTime(core);
    std::printf("%-38s %12.2f %12.2f %14.3g %14.3g\n", name, mapNs, coreNs, worst, rms);
    std::printf("RESULT name=\"%s\" map_ns=%.4f core_ns=%.4f worst_n=%.6g rms_n=%.6g\n", name, mapNs, coreNs, worst,
                rms);
  };
#define KF_VARIANT(NAME, F) \
  run(                      \
      NAME, [](double a) { return F(a); }, CoreCopy<F>(capacity, window))
  KF_VARIANT("std::log10 (double)", forceLog10);
  KF_VARIANT("std::log (double) * log10(e), the exact path", forceLn);
  KF_VARIANT("std::log2 (double) * log10(2)", forceLog2);
  KF_VARIANT("log10f (float)", forceLog10f);
  KF_VARIANT("log2f (float) * log10(2)", forceLog2f);
  KF_VARIANT("fast: bits + atanh series, 3 terms", forceAtanh3);
  KF_VARIANT("fast: bits + atanh series, 4 terms", forceAtanh4);
  KF_VARIANT("fast: bits + polynomial, degree 5", forcePoly5);
  KF_VARIANT("fast: bits + polynomial, degree 6", forcePoly6);
#undef KF_VARIANT

  // The real core on the same input, on each code path this processor has (CorePath.hpp).
  for (kf::CorePath path : {kf::CorePath::portable, kf::CorePath::avx2}) {
    if (kf::setCorePath(path) != path) continue;
    std::vector<float> history(capacity);
    kf::LoudnessToFriction real(history.data(), capacity);
    real.setWindowSamples(window);
    const double realNs = bestSecondsOf(coreRepeats,
                                        [&] {
                                          for (int i = 0; i < samples; i += 64)
                                            real.process(input.data() + i, coreOut.data() + i, 64);
                                        }) /
                          samples * 1e9;
    const std::string name = std::string("kf::LoudnessToFriction::process, ") + kf::corePathName(path);
    std::printf("%-38s %12s %12.2f\n", name.c_str(), "", realNs);
    std::printf("RESULT name=\"%s\" core_ns=%.4f\n", name.c_str(), realNs);
  }
  // Share of samples of (b) that took a logarithm (inside the clip range).
  {
    CoreCopy<forceLog10> c(capacity, window);
    c.process(input.data(), coreOut.data(), samples);
    long inside = 0;
    for (int i = 0; i < samples; ++i) inside += (coreOut[i] > float(kLoForceN) && coreOut[i] < float(kHiForceN));
    std::printf("core input: %.1f %% of samples inside the clip range\n", 100.0 * inside / samples);
  }
  return 0;
}
