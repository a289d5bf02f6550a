// A texture: band-limited spatial noise, a deterministic function of the position (the same
// texture at every visit of the same place), not of time. It is a sum of sines (plane waves in 2D)
// with spatial frequencies |f_k| drawn uniformly in [lo, hi] cycles/mm and phases drawn from the
// seed (splitmix64, so every platform draws the same):
//   1D: level(x)    = 1/2 + a * sum_k sin(2 pi f_k x + phi_k),                  16 components
//   2D: level(x, y) = 1/2 + a * sum_k sin(2 pi (fx_k x + fy_k y) + phi_k),      32 components,
//       f_k's direction uniform in angle (drawn per component: |f|, angle, phase)
//   a = 1 / (6 sqrt(count / 2))
// (a standard deviation of 1/6: +-3 sigma spans [0, 1]; the rare excursions beyond are clamped).
// 2D has twice the components: each plane wave is a field of straight stripes; with n of them the
// stripes run in n directions, on average 180 / n degrees apart, each carrying 1/n of the
// variance, so the fewer there are the more single stripe directions show. 32 (5.6 degrees, 3%
// each) is what the gallery's texture2D-raster.png shows as grain without a dominant direction, at
// a bounded cost: one fixed array, twice the 1D texture's time per sample (0.70 against 0.35 us
// per sample measured at -O3, moving; 3.4 % of a core at 48 kHz, twice that during a crossfade).
// Rendered as each wave's mean over the frame's straight travel p0 -> p1 (exact, no cancellation):
//   sin(2 pi f.mid + phi) * sinc(pi f.(p1 - p0)),  times bandLimitGain(|f.v|)
// each component fading on its own temporal frequency, the projection of its wave vector on the
// velocity: a wave whose crests run along the motion has frequency 0 and is kept at any speed.
// A change of band or seed crossfades from the old texture to the new over kCrossfadeS; each is
// a function of position, so after the fade a place feels as it will at every later visit. A
// change during a fade waits for it to end (the newest pending one wins), then fades in: replacing
// the texture being faded in would step the force by the fade weight times the difference.
#pragma once

#include <cstdint>

#include "patterns/PatternTravel.hpp"

namespace kf::patterns {

class TexturePattern {
 public:
  static constexpr int kComponents = 16;    // 1D
  static constexpr int kComponents2D = 32;  // 2D (header: why more)
  static constexpr int kMaxComponents = kComponents2D;
  static constexpr double kCrossfadeS = 0.05;

  // dimensions 2: the plane waves of (x, y); anything else: the 1D texture of x.
  explicit TexturePattern(int dimensions = 1) : twoD_(dimensions == 2) {}

  // Band edges in cycles/mm (not finite or <= 0 keep the last good; swapped if lo > hi); seed
  // any finite number (its integer part is used). The first call sets without a fade.
  void set(double loCyclesPerMm, double hiCyclesPerMm, double seed, double sampleRateHz);
  // 1D: the travel along x.
  double level(const Travel& travel, bool antialias);
  // 2D: the frame's travel from (x0, y0) to (x1, y1) mm over framePeriodS.
  double level(double x0, double y0, double x1, double y1, double framePeriodS, bool antialias);
  // The definitions (no fade, no travel): the texture of band [lo, hi] and seed at x or (x, y).
  static double at(double loCyclesPerMm, double hiCyclesPerMm, uint64_t seed, double xMm);
  static double at2D(double loCyclesPerMm, double hiCyclesPerMm, uint64_t seed, double xMm, double yMm);

  struct Components {
    int count = 0;
    double frequencyX[kMaxComponents];  // cycles/mm
    double frequencyY[kMaxComponents];  // cycles/mm, 0 in 1D
    double phase[kMaxComponents];       // rad
  };
  static void draw(double loCyclesPerMm, double hiCyclesPerMm, uint64_t seed, Components& out);
  static void draw2D(double loCyclesPerMm, double hiCyclesPerMm, uint64_t seed, Components& out);
  static double amplitude(int count = kComponents);

 private:
  struct Step {  // a frame's straight travel: its midpoint and displacement (mm), its period (s)
    double midX, midY, dx, dy, framePeriodS;
    double toX, toY;  // where the puck is now (the raw rendering)
  };
  static double render(const Components& c, const Step& step, bool antialias);
  static double sum(const Components& c, double xMm, double yMm);
  double level(const Step& step, bool antialias);
  void startFade(const Components& to);
  bool twoD_;
  Components current_{}, previous_{}, pending_{};
  bool hasPending_ = false;
  double sampleRateHz_ = 48000.0;
  double lo_ = 0.5, hi_ = 3.0;            // before the first good values: FrictionPattern.texture's defaults
  double drawnLo_ = 0.0, drawnHi_ = 0.0;  // the band current_ or pending_ was last drawn for
  uint64_t seed_ = 0;
  bool set_ = false;
  double fade_ = 1.0;      // weight of current_: 1 when no fade runs
  double fadeStep_ = 0.0;  // per sample
};

}  // namespace kf::patterns
