// What every spatial friction pattern is given: the puck's travel over the last force frame
// (1 ms), its direction and speed, and the tools the patterns share to band-limit themselves to
// what 1 ms force frames can show (ARCHITECTURE.md, "Friction patterns").
//
// A pattern is a level g in [0, 1] (force = loForce + (hiForce - loForce) * g). A pattern of
// position g(x) is rendered as its mean over the travel of the last frame, [x(t - T), x(t)]
// (a box filter in space whose length follows the speed), computed in closed form from g's
// integral; with anti-aliasing on, each harmonic k of a periodic pattern is then weighted on its
// own temporal frequency k * speed / period, down to 0 at half the frame rate (the frames' Nyquist
// frequency): the frames get no component they would fold (bandLimitedSeries). With anti-aliasing off, a pattern is g
// at the current position (sampled per audio sample: what aliases in the frames).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>

namespace kf::patterns {

// pi: M_PI is POSIX's, not C++17's (MinGW and a strict libc++ build have no M_PI).
inline constexpr double kPi = 3.14159265358979323846;

// The puck's travel over the last frame: from fromMm (T ago) to toMm (now).
struct Travel {
  double fromMm = 0.0;
  double toMm = 0.0;
  int direction = 1;           // sign of toMm - fromMm; the last direction while it is 0
  double speedMmPerS = 0.0;    // |toMm - fromMm| / framePeriodS
  double framePeriodS = 1e-3;  // T: the frame in samples over the sample rate
};

// The last frame of positions (and of one value beside them, a height), kept in a fixed ring: no
// allocation. T is round(sampleRate * framePeriodS) samples, 1..kMaxFrameSamples, so that the
// travel is exact to the sample at every rate (44.1 kHz: 44 samples, T = 0.9977 ms).
class FrameTravel {
 public:
  static constexpr int kMaxFrameSamples = 256;  // 1 ms up to 256 kHz

  void setSampleRate(double sampleRateHz, double framePeriodS);
  // Takes the next position (a non-finite one holds the last finite position, 0 before the
  // first) and value; returns the travel over the frame that ends with it.
  Travel push(float positionMm, double value = 0.0);
  // The value pushed with the position at the start of the travel last returned.
  double valueFrameAgo() const { return valueFrom_; }
  double valueNow() const { return valueTo_; }
  // The last finite position pushed (0 before the first): where a non-finite one holds the puck.
  double lastPositionMm() const { return lastPositionMm_; }
  double framePeriodS() const { return frameSamples_ / sampleRateHz_; }

 private:
  double positions_[kMaxFrameSamples] = {};
  double values_[kMaxFrameSamples] = {};
  int frameSamples_ = 48;
  double sampleRateHz_ = 48000.0;
  int next_ = 0;
  bool started_ = false;
  double lastPositionMm_ = 0.0;
  int direction_ = 1;
  double valueFrom_ = 0.0;
  double valueTo_ = 0.0;
};

// 1 up to a quarter of the frame rate, 0 from half of it on (the frames' Nyquist frequency), a
// raised cosine between: how much of a periodic part of temporal frequency frequencyHz is kept.
double bandLimitGain(double frequencyHz, double framePeriodS);

// x - floor(x) in [0, 1); 0 for NaN and +-inf (cycles beyond double's range).
inline double fractionOf(double x) {
  const double f = x - std::floor(x);
  return f < 1.0 ? f : 0.0;
}

// A coordinate in cycles of a period (mm): u = x / period + phase. Changing the period keeps u
// where the puck is (phase continuity, a zoom about the puck, as SpatialBufRd's keep); before any
// change u = x / period, so the pattern starts its cycles at x = 0.
class PeriodicCoordinate {
 public:
  // A period that is not finite and > 0 is ignored (the caller keeps the last good one).
  void setPeriod(double periodMm, double anchorMm);
  double cycles(double xMm) const { return xMm / periodMm_ + phase_; }
  double periodMm() const { return periodMm_; }

 private:
  double periodMm_ = 1.0;
  double phase_ = 0.0;
  bool set_ = false;
};

// The mean over [u0, u1] (cycles, in either order) of a periodic function of period 1, from its
// integral over one period and its partial integral partial(f) = integral of g over [0, f],
// f in [0, 1); point(f) when the interval is shorter than tinyCycles (the limit of the mean).
template <class Partial, class Point>
double periodicMean(double u0, double u1, double perPeriod, Partial partial, Point point) {
  if (u1 < u0) std::swap(u0, u1);
  const double length = u1 - u0;
  constexpr double kTinyCycles = 1e-9;
  if (!(length >= kTinyCycles)) return point(fractionOf(u1));
  const double whole0 = std::floor(u0), whole1 = std::floor(u1);
  const double f0 = std::min(u0 - whole0, 1.0), f1 = std::min(u1 - whole1, 1.0);
  return ((whole1 - whole0) * perPeriod + partial(f1) - partial(f0)) / length;
}

// The complex Fourier coefficients C_1..C_kMaxHarmonics (index k - 1) of a periodic level of
// period 1 cycle: g(u) = mean + sum_k 2 Re(C_k e^(i 2 pi k u)). Each pattern has them in closed form.
constexpr int kMaxHarmonics = 64;
using Harmonics = std::array<std::complex<double>, kMaxHarmonics>;

// The gain of harmonic k in the band-limited series, r = k / kCut: the cubic B-spline
// 1 - 6 r^2 + 6 |r|^3 up to |r| = 1/2, 2 (1 - |r|)^3 up to 1, 0 beyond. Its transform is sinc^4,
// never negative: the series is the pattern smoothed by a kernel >= 0 of unit mass, so it stays
// within the pattern's range (no ringing past 0 or 1), unlike a flat pass band.
inline double splineGain(double r) {  // inline: it runs once per harmonic in bandLimitedSeriesTo's loop
  const double a = std::fabs(r);
  if (a <= 0.5) return 1.0 - 6.0 * a * a + 6.0 * a * a * a;
  return a < 1.0 ? 2.0 * (1.0 - a) * (1.0 - a) * (1.0 - a) : 0.0;
}

// What a pattern may leave folding: a harmonic k >= kStop that the box keeps folds as a line of
// amplitude 2 |C_k| sinc(pi k length) <= (4 / pi) |C_k| (length = 1 / (2 kStop) cycles, so the
// sinc is <= 2 kStop / (pi k) <= 2 / pi), in level units (N per N of force range). 1e-5: the
// project's 1e-5 N bar on a range up to 1 N.
inline constexpr double kNegligibleFold = 1e-5;
// A pattern's sharpness, kSharp: the harmonic from which on (4 / pi) |C_k| <= kNegligibleFold, from
// a bound on |C_k| of the form amplitude / k^power (each pattern's, in its header): 0 where every
// harmonic is below it already (amplitude <= the level at k = 1).
double sharpHarmonic(double amplitude, double power);

// The level of a periodic pattern over the travel [u0, u1] (cycles), band-limited to the 1 ms
// frames. kStop = (frame rate / 2) / (speed / period): the first harmonic at the frames' Nyquist
// frequency; kSharp: the pattern's (sharpHarmonic). Up to kStop = kMaxHarmonics (from 500 * period
// / 64 mm/s up), the box-filtered harmonics (mean over the travel of e^(i 2 pi k u):
// e^(i 2 pi k mid) sinc(pi k length)) weighted by splineGain(k / kStop): no component at or above
// the Nyquist frequency is left (exact). Past it, up to kFull = max(kMaxHarmonics, kSharp), the
// same series cut at kMaxHarmonics: below the Nyquist frequency, but smoother than the pattern
// where it has harmonics past kMaxHarmonics (the price of a bounded cost: a sharp pattern keeps
// only 64 harmonics until it is slow enough). From kStop = 2 kFull down to rest: boxed, the
// closed-form mean over the travel (the full rendering), whose harmonics past kStop >= kSharp fold
// below kNegligibleFold. Between, h boxed + (1 - h) series, h rising 0 -> 1 (raised cosine in
// kStop): continuous in speed.
double bandLimitedSeries(double boxed, double mean, const Harmonics& c, double u0, double u1, const Travel& travel,
                         double periodMm, double kSharp);
// One periodic level as bandLimitedSeriesTo takes it: its mean over the travel (boxed), over a
// period, and its harmonics.
struct PeriodicLevel {
  double boxed;
  double mean;
  const Harmonics* harmonics;
};
// bandLimitedSeries with kStop given (the first harmonic that may not be kept: a 2D pattern shares
// the frames' Nyquist frequency between its axes, GridBumpsPattern; NaN or inf: boxed), for N
// levels over the same travel at once, element i as if alone (to the last bit): the per-harmonic
// rotations, spline gain and sinc, which depend only on the travel and kStop, are computed once for
// all N (GridBumpsPattern: an axis's climb and height).
template <std::size_t N>
std::array<double, N> bandLimitedSeriesTo(double kStop, double kSharp, const std::array<PeriodicLevel, N>& levels,
                                          double u0, double u1);

inline double clampLevel(double g) { return g > 0.0 ? (g < 1.0 ? g : 1.0) : 0.0; }

}  // namespace kf::patterns
