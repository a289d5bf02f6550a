// SpeedGovernor: friction that steers the movement towards a target speed. Below the target the
// force is the resting level loForceN; above it the force rises by gainNPerMmPerS for every mm/s
// of excess, up to hiForceN:
//   force = clamp(loForceN + gain * max(0, |v| - target), loForceN, hiForceN),   |v| = hypot(vx, vy)
// so a hand pushing harder than friction at the target speed is held near it: at a steady push P
// the puck settles where the force equals P, target + (P - loForceN) / gain (Coulomb friction
// against a push, the simulated hand). A non-finite speed gives loForceN.
#pragma once

#include <cmath>

namespace kf {

struct GovernorSettings {
  double targetMmPerS = 0.0;    // >= 0
  double gainNPerMmPerS = 0.0;  // >= 0
  double loForceN = 0.0;
  double hiForceN = 0.0;  // >= loForceN
};

inline float governorForceN(double speedXMmPerS, double speedYMmPerS, const GovernorSettings& g) {
  const double speed = std::hypot(speedXMmPerS, speedYMmPerS);
  if (!std::isfinite(speed)) return static_cast<float>(g.loForceN);
  const double excess = speed > g.targetMmPerS ? speed - g.targetMmPerS : 0.0;
  const double force = g.loForceN + g.gainNPerMmPerS * excess;
  return static_cast<float>(force < g.hiForceN ? force : g.hiForceN);
}

// out[i] = governorForceN(vx[i * xStride], vy[i * yStride], g); a stride is 1 for audio rate, 0
// for a value held over the block. out may share memory with vx or vy.
inline void governorBlock(const float* vx, int xStride, const float* vy, int yStride, const GovernorSettings& g,
                          float* out, int numSamples) {
  for (int i = 0; i < numSamples; ++i) out[i] = governorForceN(vx[i * xStride], vy[i * yStride], g);
}

}  // namespace kf
