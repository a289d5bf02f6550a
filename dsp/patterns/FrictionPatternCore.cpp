#include "patterns/FrictionPatternCore.hpp"

namespace kf::patterns {

ForceRange usableForceRange(double loN, double hiN) {
  ForceRange r;
  if (std::isfinite(loN)) r.loN = std::max(0.0, loN);
  if (std::isfinite(hiN)) r.hiN = std::max(0.0, hiN);
  return r;
}

FrictionPatternCore::FrictionPatternCore(PatternKind kind, double sampleRateHz, double framePeriodS)
    : kind_(kind), sampleRateHz_(sampleRateHz), texture_(kind == PatternKind::Texture2D ? 2 : 1) {
  travel_.setSampleRate(sampleRateHz, framePeriodS);
}

void FrictionPatternCore::setParameters(double p1, double p2, double p3, float anchorPositionMm) {
  // A NaN/inf anchor (the block's first position) is held like any position: the last finite one.
  // Left non-finite, a period change would take effect without keeping the phase.
  const double anchorMm = std::isfinite(anchorPositionMm) ? anchorPositionMm : travel_.lastPositionMm();
  switch (kind_) {
    case PatternKind::Grating:
      return grating_.set(p1, p2, p3, anchorMm);
    case PatternKind::Bumps:
      return bumps_.set(p1, p2, p3 > 0.5, anchorMm);
    case PatternKind::Detents:
      return detents_.set(p1, p2, anchorMm);
    case PatternKind::Texture:
    case PatternKind::Texture2D:
      return texture_.set(p1, p2, p3, sampleRateHz_);
    case PatternKind::Viscous:
      return viscous_.set(p1);
    case PatternKind::StickSlip:
      return stickSlip_.set(p1, p2);
    case PatternKind::Slope:
      return slope_.setFullSlope(p2);
    case PatternKind::Bumps2D:
      return gridBumps_.set(p1, p2, p3, anchorMm, lastYMm_);
  }
}

double FrictionPatternCore::level(const Travel& travel) {
  switch (kind_) {
    case PatternKind::Grating:
      return grating_.level(travel, antialias_);
    case PatternKind::Bumps:
      return bumps_.level(travel, antialias_);
    case PatternKind::Detents:
      return detents_.level(travel, antialias_);
    case PatternKind::Texture:
      return texture_.level(travel, antialias_);
    case PatternKind::Viscous:
      return viscous_.level(travel);
    case PatternKind::StickSlip:
      return stickSlip_.level(travel);
    case PatternKind::Slope:
      return slope_.level(travel, travel_.valueFrameAgo(), travel_.valueNow());
    case PatternKind::Bumps2D:
      return gridBumps_.level(travel, travel_.valueFrameAgo(), travel_.valueNow(), antialias_);
    case PatternKind::Texture2D:
      return texture_.level(travel.fromMm, travel_.valueFrameAgo(), travel.toMm, travel_.valueNow(),
                            travel.framePeriodS, antialias_);
  }
  return 0.0;
}

void FrictionPatternCore::process(const float* positionMm, int positionStride, const float* height, int heightStride,
                                  float* forceN, int numSamples) {
  const bool twoD = isTwoD(kind_);
  const bool withHeight = (kind_ == PatternKind::Slope || twoD) && height != nullptr;
  const double span = range_.hiN - range_.loN;
  for (int i = 0; i < numSamples; ++i) {
    // Both inputs read before the output is written: forceN may alias either.
    const float x = positionMm[i * positionStride];
    double h = withHeight ? static_cast<double>(height[i * heightStride]) : 0.0;
    if (twoD) h = lastYMm_ = std::isfinite(h) ? h : lastYMm_;
    lastLevel_ = level(travel_.push(x, h));
    forceN[i] = static_cast<float>(range_.loN + span * lastLevel_);
  }
}

}  // namespace kf::patterns
