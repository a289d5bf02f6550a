#include "PatternTravel.hpp"

namespace kf::patterns {

void FrameTravel::setSampleRate(double sampleRateHz, double framePeriodS) {
  sampleRateHz_ = sampleRateHz > 0.0 && std::isfinite(sampleRateHz) ? sampleRateHz : 48000.0;
  const double wanted = std::round(sampleRateHz_ * framePeriodS);
  frameSamples_ = wanted >= 1.0 ? (wanted <= kMaxFrameSamples ? static_cast<int>(wanted) : kMaxFrameSamples) : 1;
  started_ = false;
  next_ = 0;
}

Travel FrameTravel::push(float positionMm, double value) {
  if (std::isfinite(positionMm)) lastPositionMm_ = positionMm;
  const double x = lastPositionMm_;
  if (!started_) {  // the first position fills the frame: no travel before it
    std::fill_n(positions_, frameSamples_, x);
    std::fill_n(values_, frameSamples_, value);
    started_ = true;
  }
  // The slot written now held the position one frame (frameSamples_ samples) ago.
  const double from = positions_[next_];
  valueFrom_ = values_[next_];
  valueTo_ = value;
  positions_[next_] = x;
  values_[next_] = value;
  if (++next_ == frameSamples_) next_ = 0;
  const double travel = x - from;
  if (travel > 0.0) direction_ = 1;
  if (travel < 0.0) direction_ = -1;
  const double periodS = framePeriodS();
  return Travel{from, x, direction_, std::fabs(travel) / periodS, periodS};
}

double bandLimitGain(double frequencyHz, double framePeriodS) {
  const double stopHz = 0.5 / framePeriodS, passHz = 0.5 * stopHz;
  if (!(frequencyHz > passHz)) return 1.0;  // NaN speed: the pattern as it is
  if (frequencyHz >= stopHz) return 0.0;
  return 0.5 * (1.0 + std::cos(M_PI * (frequencyHz - passHz) / (stopHz - passHz)));
}

void PeriodicCoordinate::setPeriod(double periodMm, double anchorMm) {
  if (!(periodMm > 0.0) || !std::isfinite(periodMm)) return;
  if (set_ && periodMm == periodMm_) return;
  // Beyond double's range (a huge position over a tiny period) fractionOf gives 0, not NaN.
  if (set_ && std::isfinite(anchorMm)) phase_ = fractionOf(cycles(anchorMm) - anchorMm / periodMm);
  periodMm_ = periodMm;
  set_ = true;
}

}  // namespace kf::patterns
