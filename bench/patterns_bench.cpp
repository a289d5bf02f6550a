// FrictionPattern's kinds, speed against error: per kind, at 5 and 300 mm/s over a fine pattern
// (0.2 mm; the 2D kind along 30 degrees), the core's CPU time per sample with anti-aliasing on and
// off, measured side by side (the two interleaved in every round, each round a fresh core on the
// same path), and LoudnessToFriction's per sample on noise in the same rounds; and the alias that
// anti-aliasing removes: the largest non-DC amplitude (N) of the 1 ms frames' spectrum at 300 mm/s,
// on and off, measured as the tests measure it (tests/dsp/patterns/ForceFrameSpectrum.hpp).
// Prints one JSON object (bench/kfbench/patterns.py reads it).
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "ForceFrameSpectrum.hpp"
#include "LoudnessToFriction.hpp"
#include "patterns/FrictionPatternCore.hpp"

namespace {

using kf::patterns::FrictionPatternCore;
using kf::patterns::kPi;
using kf::patterns::PatternKind;

constexpr double kRate = 48000;
constexpr int kBlock = 64;
constexpr double kFineMm = 0.2;  // the tests' fine pattern
constexpr double kAngleRad = kPi / 6;

struct Kind {
  const char* name;
  PatternKind kind;
  double p1, p2, p3;  // FrictionPatternCore::setParameters's, on the fine pattern
  // Whether the frames' largest non-DC line at 300 mm/s is an alias: not for a coarse pattern
  // (its harmonics below 500 Hz are the pattern) nor texture2D (its waves whose crests run along
  // the motion are kept at any speed; its test measures the folded lines).
  bool aliasMeasured = true;
};

// Every kind on a 0.2 mm pattern where it has one: the speed kinds (viscous, stickSlip) have none;
// slope is given the height of 0.2 mm raised-cosine bumps (steepest slope pi / 0.2 per mm).
const Kind kKinds[] = {
    {"grating", PatternKind::Grating, kFineMm, 0.5, 0.02},
    {"bumps", PatternKind::Bumps, kFineMm, 0.1, 0},
    {"detents", PatternKind::Detents, kFineMm, 0.8, 0},
    {"texture", PatternKind::Texture, 3, 1 / kFineMm, 11},
    {"viscous", PatternKind::Viscous, 300, 0, 0},
    {"stickSlip", PatternKind::StickSlip, 30, 10, 0},
    {"slope", PatternKind::Slope, 0, kPi / kFineMm, 0},
    {"bumps2D", PatternKind::Bumps2D, kFineMm, kFineMm, 0.1},
    {"texture2D", PatternKind::Texture2D, 3, 1 / kFineMm, 11, false},
    // Coarse patterns, where the sharp ones keep the 64-harmonic series at slow speeds (kSharp):
    // the most a pattern costs.
    {"grating-4mm", PatternKind::Grating, 4, 0.5, 0, false},
    {"bumps-10mm", PatternKind::Bumps, 10, 0.625, 0, false},
    {"bumps2D-4mm", PatternKind::Bumps2D, 4, 4, 1, false},
};

// The path at speedMmPerS for samples: x, and the second signal (y along 30 degrees for the 2D
// kinds, the height under x for slope, none otherwise).
struct Path {
  std::vector<float> x, second;
};

Path path(const Kind& k, double speedMmPerS, size_t samples) {
  Path p;
  const bool twoD = isTwoD(k.kind);
  const double vx = twoD ? speedMmPerS * std::cos(kAngleRad) : speedMmPerS;
  for (size_t i = 0; i < samples; ++i) {
    const double t = i / kRate, x = 0.013 + vx * t;
    p.x.push_back(static_cast<float>(x));
    if (twoD) p.second.push_back(static_cast<float>(0.031 + speedMmPerS * std::sin(kAngleRad) * t));
    if (k.kind == PatternKind::Slope)
      p.second.push_back(static_cast<float>(0.5 - 0.5 * std::cos(2 * kPi * x / kFineMm)));
  }
  return p;
}

// Runs a fresh core over the path as the UGen does (parameters per block); the forces.
std::vector<float> render(const Kind& k, const Path& p, bool antialias) {
  FrictionPatternCore core(k.kind, kRate);
  core.setAntialias(antialias);
  std::vector<float> force(p.x.size());
  const float* second = p.second.empty() ? nullptr : p.second.data();
  for (size_t i = 0; i < p.x.size(); i += kBlock) {
    const int n = static_cast<int>(std::min<size_t>(kBlock, p.x.size() - i));
    core.setParameters(k.p1, k.p2, k.p3, p.x[i]);
    core.process(p.x.data() + i, 1, second ? second + i : nullptr, 1, force.data() + i, n);
  }
  return force;
}

// This thread's CPU time (s): another process on the core does not count.
double threadSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

float sink = 0;  // keeps the results alive

double patternNs(const Kind& k, const Path& p, bool antialias) {
  const double t0 = threadSeconds();
  const auto f = render(k, p, antialias);
  const double s = threadSeconds() - t0;
  sink += f.back();
  return s * 1e9 / p.x.size();
}

// LoudnessToFriction (the paper's mapping, its 1 ms window) on noise, in blocks, per sample.
double loudnessNs(const std::vector<float>& noise) {
  const int n = kf::windowSamples(kRate, 1e-3, 1024);
  std::vector<float> history(1024), out(kBlock);
  kf::LoudnessToFriction ltf(history.data(), 1024);
  ltf.setWindowSamples(n);
  const double t0 = threadSeconds();
  for (size_t i = 0; i + kBlock <= noise.size(); i += kBlock) {
    ltf.process(noise.data() + i, out.data(), kBlock);
    sink += out[0];
  }
  return (threadSeconds() - t0) * 1e9 / noise.size();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s + "]";
}

}  // namespace

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::atoi(argv[1]) : 9;
  const size_t samples = static_cast<size_t>(0.5 * kRate);
  const double speeds[] = {5.0, 300.0};
  std::vector<float> noise(samples);
  unsigned state = 1;
  for (float& a : noise) a = static_cast<float>((state = state * 1664525u + 1013904223u) >> 8) / (1 << 24) - 0.5f;

  // Per kind and speed, ns per sample on and off in every round, and LoudnessToFriction's.
  struct Case {
    const Kind* kind;
    double speed;
    Path path;
    std::vector<double> on, off;
  };
  std::vector<Case> cases;
  for (const Kind& k : kKinds)
    for (double v : speeds) cases.push_back({&k, v, path(k, v, samples), {}, {}});
  std::vector<double> loudness;
  for (int r = 0; r < rounds; ++r) {
    loudness.push_back(loudnessNs(noise));
    for (Case& c : cases) {
      // Alternate which goes first, so neither always runs on a cache warmed by the other.
      const bool onFirst = r % 2 == 0;
      if (onFirst) c.on.push_back(patternNs(*c.kind, c.path, true));
      c.off.push_back(patternNs(*c.kind, c.path, false));
      if (!onFirst) c.on.push_back(patternNs(*c.kind, c.path, true));
    }
  }

  std::printf(
      "{\"sampleRateHz\": %g, \"block\": %d, \"rounds\": %d, \"seconds\": %g, \"fineMm\": %g, \"angleDeg\": %g,\n",
      kRate, kBlock, rounds, samples / kRate, kFineMm, kAngleRad * 180 / kPi);
  std::printf(" \"loudnessNs\": %s,\n \"cases\": [\n", list(loudness).c_str());
  for (size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    std::vector<double> ratio, vsLoudness;
    for (int r = 0; r < rounds; ++r) {
      ratio.push_back(c.on[r] / c.off[r]);
      vsLoudness.push_back(c.on[r] / loudness[r]);
    }
    std::printf(
        "  {\"kind\": \"%s\", \"speedMmPerS\": %g, \"p\": [%g, %g, %g], \"nsOn\": %s, \"nsOff\": %s,\n"
        "   \"nsOnMedian\": %g, \"nsOffMedian\": %g, \"onOverOff\": %g, \"onOverLoudness\": %g",
        c.kind->name, c.speed, c.kind->p1, c.kind->p2, c.kind->p3, list(c.on).c_str(), list(c.off).c_str(),
        median(c.on), median(c.off), median(ratio), median(vsLoudness));
    if (c.speed == 300.0 && c.kind->aliasMeasured) {
      // The tests' alias measure: frames from 10 ms on (the first frames hold the start).
      const Path fast = path(*c.kind, c.speed, static_cast<size_t>(0.3 * kRate));
      const double aliasOn =
          kf::spectrum::largestNonDcAmplitude(kf::spectrum::frames(render(*c.kind, fast, true), 480));
      const double aliasOff =
          kf::spectrum::largestNonDcAmplitude(kf::spectrum::frames(render(*c.kind, fast, false), 480));
      std::printf(",\n   \"aliasOnN\": %.6g, \"aliasOffN\": %.6g", aliasOn, aliasOff);
    }
    std::printf("}%s\n", i + 1 < cases.size() ? "," : "");
  }
  std::printf(" ],\n \"sink\": %g}\n", sink);
  return 0;
}
