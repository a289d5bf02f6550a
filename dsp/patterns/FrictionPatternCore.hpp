// One friction pattern of a kind chosen at construction, run over blocks: position (mm) in,
// force (N) out, force = loForce + (hiForce - loForce) * level. What FrictionPattern (the
// UGen) runs; the patterns themselves are in their own files (GratingPattern, HeightSlopePattern,
// DetentPattern, TexturePattern, SpeedFriction). Nothing here allocates.
#pragma once

#include "PaperProfile.hpp"
#include "patterns/DetentPattern.hpp"
#include "patterns/GratingPattern.hpp"
#include "patterns/GridBumpsPattern.hpp"
#include "patterns/HeightSlopePattern.hpp"
#include "patterns/PatternTravel.hpp"
#include "patterns/SpeedFriction.hpp"
#include "patterns/TexturePattern.hpp"

namespace kf::patterns {

// The codes of FrictionPattern's kind input. Parameters p1, p2, p3 by kind:
//   grating: period (mm), duty (0..1), edge (mm)      bumps: period (mm), width (mm), valleys (0/1)
//   detents: spacing (mm), crest (0..1)               texture: lo, hi (cycles/mm), seed
//   viscous: fullSpeed (mm/s)                         stickSlip: slipSpeed, stickSpeed (mm/s)
//   slope: p1 is the height signal (audio rate), p2 fullSlope (height units per mm)
//   bumps2D: spacingX, spacingY, width (mm); the second signal is y (mm)
//   texture2D: lo, hi (cycles/mm), seed; the second signal is y (mm)
enum class PatternKind : int {
  Grating = 0,
  Bumps = 1,
  Detents = 2,
  Texture = 3,
  Viscous = 4,
  StickSlip = 5,
  Slope = 6,
  Bumps2D = 7,
  Texture2D = 8
};
constexpr int kPatternKinds = 9;

// The kinds that read y (mm) as their second signal.
constexpr bool isTwoD(PatternKind kind) { return kind == PatternKind::Bumps2D || kind == PatternKind::Texture2D; }

struct ForceRange {
  double loN = paper::mapping::loForceN;
  double hiN = paper::mapping::hiForceN;
};

// Not finite: the paper mapping's loForce / hiForce; negative: 0 N (friction never pushes).
// Reversed bounds are kept (the level then lowers the force).
ForceRange usableForceRange(double loN, double hiN);

class FrictionPatternCore {
 public:
  FrictionPatternCore(PatternKind kind, double sampleRateHz, double framePeriodS = paper::device::forceFramePeriodS);

  PatternKind kind() const { return kind_; }
  // Per block, before process(): the parameters (see PatternKind) and where the puck is (the
  // anchor of phase-continuous period changes).
  void setParameters(double p1, double p2, double p3, float anchorMm);
  void setForceRange(const ForceRange& range) { range_ = range; }
  void setAntialias(bool on) { antialias_ = on; }

  // position and height at stride 1 (audio rate) or 0 (held); height is read for Slope only, and
  // is y (mm) for the 2D kinds (a NaN/inf y holds the last finite one, 0 before the first); nullptr
  // otherwise. forceN may share memory with position or height.
  void process(const float* positionMm, int positionStride, const float* height, int heightStride, float* forceN,
               int numSamples);
  // The level process() gave last (0..1).
  double lastLevel() const { return lastLevel_; }

 private:
  double level(const Travel& travel);

  PatternKind kind_;
  double sampleRateHz_;
  FrameTravel travel_;
  ForceRange range_;
  bool antialias_ = true;
  double lastLevel_ = 0.0;
  GratingPattern grating_;
  BumpPattern bumps_;
  DetentPattern detents_;
  TexturePattern texture_;
  ViscousFriction viscous_;
  StickSlipFriction stickSlip_;
  SlopeOfHeight slope_;
  GridBumpsPattern gridBumps_;
  double lastYMm_ = 0.0;
};

}  // namespace kf::patterns
