// DeterministicRandom: a seeded generator whose numbers are the same on every platform and
// standard library (std::normal_distribution is not), so simulated runs repeat bit for bit.
#pragma once

#include <cmath>
#include <cstdint>

namespace kf {

class DeterministicRandom {
 public:
  explicit DeterministicRandom(uint64_t seed = 1) : state_(seed) {}

  // splitmix64
  uint64_t nextU64() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(nextU64() >> 11) * 0x1.0p-53; }
  // Standard normal (Box-Muller, one value per call).
  double gaussian() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

 private:
  uint64_t state_;
};

}  // namespace kf
