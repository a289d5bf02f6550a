#include "patterns/PatternTravel.hpp"

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
  return 0.5 * (1.0 + std::cos(kPi * (frequencyHz - passHz) / (stopHz - passHz)));
}

double sharpHarmonic(double amplitude, double power) {
  const double level = 0.25 * kPi * kNegligibleFold;  // |C_k| at which (4 / pi) |C_k| is the level
  if (!(amplitude > level)) return 0.0;
  return std::pow(amplitude / level, 1.0 / power);
}

double bandLimitedSeries(double boxed, double mean, const Harmonics& c, double u0, double u1, const Travel& travel,
                         double periodMm, double kSharp) {
  const double f1 = travel.speedMmPerS / periodMm;  // the fundamental's temporal frequency (Hz)
  if (!(f1 > 0.0)) return boxed;                    // at rest (or NaN): the pattern as it is
  return bandLimitedSeriesTo<1>(0.5 / travel.framePeriodS / f1, kSharp, {PeriodicLevel{boxed, mean, &c}}, u0, u1)[0];
}

template <std::size_t N>
std::array<double, N> bandLimitedSeriesTo(double kStop, double kSharp, const std::array<PeriodicLevel, N>& levels,
                                          double u0, double u1) {
  std::array<double, N> out;
  // NaN kSharp counts as kMaxHarmonics (std::max keeps its first argument).
  const double kFull = std::max(static_cast<double>(kMaxHarmonics), kSharp);
  if (!(kStop < 2.0 * kFull)) {  // slow: the closed form, h = 1
    for (std::size_t i = 0; i < N; ++i) out[i] = levels[i].boxed;
    return out;
  }
  const double h = kStop <= kFull ? 0.0 : 0.5 * (1.0 - std::cos(kPi * (kStop - kFull) / kFull));
  const double kCut = std::min(kStop, static_cast<double>(kMaxHarmonics));
  // Rotations stepped once per harmonic: e^(i 2 pi k mid) and e^(i pi k length) (its sine over
  // pi k length is the box's sinc).
  const double mid = 0.5 * (u0 + u1), length = std::fabs(u1 - u0);
  const std::complex<double> stepMid = std::polar(1.0, 2.0 * kPi * fractionOf(mid));
  const std::complex<double> stepBox = std::polar(1.0, kPi * length);
  std::complex<double> atMid = stepMid, box = stepBox;
  std::array<double, N> series;
  for (std::size_t i = 0; i < N; ++i) series[i] = levels[i].mean;
  for (int k = 1; k < kCut; ++k) {
    const double x = kPi * k * length;
    const double sinc = x < 1e-9 ? 1.0 : box.imag() / x;
    const double gain = splineGain(k / kCut) * 2.0;
    for (std::size_t i = 0; i < N; ++i) {
      // Re(C_k e^(i 2 pi k mid)) written out: the complex product's NaN/inf recovery (__muldc3) is
      // not needed for the finite coefficients and rotations, and its check costs in this loop.
      const std::complex<double> c = (*levels[i].harmonics)[k - 1];
      series[i] += gain * (c.real() * atMid.real() - c.imag() * atMid.imag()) * sinc;
    }
    atMid *= stepMid;
    box *= stepBox;
  }
  for (std::size_t i = 0; i < N; ++i) out[i] = h * levels[i].boxed + (1.0 - h) * series[i];
  return out;
}
template std::array<double, 1> bandLimitedSeriesTo<1>(double, double, const std::array<PeriodicLevel, 1>&, double,
                                                      double);
template std::array<double, 2> bandLimitedSeriesTo<2>(double, double, const std::array<PeriodicLevel, 2>&, double,
                                                      double);

void PeriodicCoordinate::setPeriod(double periodMm, double anchorMm) {
  if (!(periodMm > 0.0) || !std::isfinite(periodMm)) return;
  if (set_ && periodMm == periodMm_) return;
  // Beyond double's range (a huge position over a tiny period) fractionOf gives 0, not NaN.
  if (set_ && std::isfinite(anchorMm)) phase_ = fractionOf(cycles(anchorMm) - anchorMm / periodMm);
  periodMm_ = periodMm;
  set_ = true;
}

}  // namespace kf::patterns
