// A texture: band-limited spatial noise, a deterministic function of the position (the same
// texture at every visit of the same place), not of time. It is a sum of kComponents sines with
// spatial frequencies drawn uniformly in [lo, hi] cycles/mm and phases drawn from the seed
// (splitmix64, so every platform draws the same):
//   level(x) = 1/2 + a * sum_k sin(2 pi f_k x + phi_k),  a = 1 / (6 sqrt(kComponents / 2))
// (a standard deviation of 1/6: +-3 sigma spans [0, 1]; the rare excursions beyond are clamped).
// Rendered as each sine's mean over the frame's travel (sin(mid) * sinc(half), exact, no
// cancellation) times bandLimitGain(speed * f_k): each component fades on its own frequency.
// A change of band or seed crossfades from the old texture to the new over kCrossfadeS; each is
// a function of position, so after the fade a place feels as it will at every later visit. A
// change during a fade waits for it to end (the newest pending one wins), then fades in: replacing
// the texture being faded in would step the force by the fade weight times the difference.
#pragma once

#include <cstdint>

#include "PatternTravel.hpp"

namespace kf::patterns {

class TexturePattern {
 public:
  static constexpr int kComponents = 16;
  static constexpr double kCrossfadeS = 0.05;

  // Band edges in cycles/mm (not finite or <= 0 keep the last good; swapped if lo > hi); seed
  // any finite number (its integer part is used). The first call sets without a fade.
  void set(double loCyclesPerMm, double hiCyclesPerMm, double seed, double sampleRateHz);
  double level(const Travel& travel, bool antialias);
  // The definition: the texture of band [lo, hi] and seed at position x (no fade, no travel).
  static double at(double loCyclesPerMm, double hiCyclesPerMm, uint64_t seed, double xMm);

  struct Components {
    double frequency[kComponents];  // cycles/mm
    double phase[kComponents];      // rad
  };
  static void draw(double loCyclesPerMm, double hiCyclesPerMm, uint64_t seed, Components& out);
  static double amplitude();

 private:
  static double render(const Components& c, const Travel& travel, bool antialias);
  void startFade(const Components& to);
  Components current_{}, previous_{}, pending_{};
  bool hasPending_ = false;
  double sampleRateHz_ = 48000.0;
  double lo_ = 0.5, hi_ = 2.0;
  uint64_t seed_ = 0;
  bool set_ = false;
  double fade_ = 1.0;      // weight of current_: 1 when no fade runs
  double fadeStep_ = 0.0;  // per sample
};

}  // namespace kf::patterns
