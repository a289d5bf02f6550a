// Detents: the rotary knob with stepwise counterforces the pilot's subject described. Detents sit
// every `spacing` mm from x = 0. Leaving one, the counterforce builds up linearly to the full
// level at the crest (a fraction c of the spacing, in the direction of motion), then drops to the
// minimum: the puck falls into the next detent. Direction-aware: the cycle is measured from the
// detent behind the puck in the direction it moves (u' = u moving +, 1 - u moving -), so
// turning back towards the detent just left is free:
//   level(u') = u' / c on [0, c),  0 on [c, 1)
// Rendered as its mean over the frame's travel (closed form), band-limited to the speed. Its
// harmonics in u' (a = 2 pi k): C_k = (1/c) integral of u' e^(-i a u') over [0, c)
//   = i e^(-i a c) / a + (e^(-i a c) - 1) / (a^2 c),
// so |C_k| <= 1 / (2 pi k) + 1 / (2 pi^2 c k^2) <= 1 / (pi k) from k = 1 / (pi c) on (the drop at the
// crest: as sharp as a hard edge; PatternTravel.hpp's sharpHarmonic).
#pragma once

#include "patterns/PatternTravel.hpp"

namespace kf::patterns {

class DetentPattern {
 public:
  // Spacing not finite and > 0 and crest not finite keep the last good one; crest is clamped to
  // [1e-6, 1]. A change of spacing keeps the phase at anchorMm.
  void set(double spacingMm, double crest, double anchorMm);
  double level(const Travel& travel, bool antialias) const;
  // The definition at cycle fraction f (measured along +1) moving in direction (+1, -1).
  double at(double f, int direction) const;
  double mean() const { return 0.5 * crest_; }
  double sharpHarmonic() const { return sharp_; }  // PatternTravel.hpp's kSharp

 private:
  // In the direction's own cycles u' (increasing along the motion): level and its integral.
  double alongMotion(double g) const { return g < crest_ ? g / crest_ : 0.0; }
  double integralAlongMotion(double g) const { return g < crest_ ? g * g / (2.0 * crest_) : 0.5 * crest_; }
  PeriodicCoordinate coordinate_;
  double crest_ = 0.5;
  Harmonics harmonics_{};
  double harmonicsCrest_ = -1.0;
  double sharp_ = 0.0;  // sharpHarmonic of harmonics_
};

}  // namespace kf::patterns
