// How the pattern tests (and bench/patterns_bench.cpp) measure an alias: a force at 48 kHz cut
// into the device's 1 ms force frames (their means), and the largest amplitude (N) of the
// frames' spectrum away from DC. One definition, so that the bench's alias figures are the
// tests' own measure.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "patterns/PatternTravel.hpp"

namespace kf::spectrum {

// 1 ms frame means of a force at 48 kHz (48 samples each) from sample `from` on.
inline std::vector<double> frames(const std::vector<float>& f, size_t from) {
  std::vector<double> out;
  for (size_t i = from; i + 48 <= f.size(); i += 48) {
    double s = 0;
    for (size_t k = 0; k < 48; ++k) s += f[i + k];
    out.push_back(s / 48);
  }
  return out;
}

// The largest amplitude of v's spectrum away from DC (Hann window, amplitude-normalized; bins
// from 3 on, above the window's main lobe at DC).
inline double largestNonDcAmplitude(const std::vector<double>& v) {
  using kf::patterns::kPi;
  const size_t n = v.size();
  double mean = 0;
  for (double a : v) mean += a;
  mean /= n;
  double best = 0, wsum = 0;
  for (size_t i = 0; i < n; ++i) wsum += 0.5 - 0.5 * std::cos(2 * kPi * i / n);
  for (size_t k = 3; k < n / 2; ++k) {
    std::complex<double> acc = 0;
    for (size_t i = 0; i < n; ++i)
      acc += (v[i] - mean) * (0.5 - 0.5 * std::cos(2 * kPi * i / n)) * std::polar(1.0, -2 * kPi * k * i / n);
    best = std::max(best, 2 * std::abs(acc) / wsum);
  }
  return best;
}

}  // namespace kf::spectrum
