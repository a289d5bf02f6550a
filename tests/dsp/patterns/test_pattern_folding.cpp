// Sharp patterns at slow and middle speeds (kStop >= kMaxHarmonics, PatternTravel.hpp): no
// harmonic folds into the 1 ms force frames above kNegligibleFold, and the level is continuous in
// speed across the series / blend / closed-form thresholds. Positions in double, each pattern
// given its frame's travel directly: the frames are exactly periodic (no float rounding), so their
// spectrum is read exactly with a plain DFT of one period.
#include <catch2/catch.hpp>

#include <cmath>
#include <complex>
#include <functional>
#include <vector>

#include "patterns/DetentPattern.hpp"
#include "patterns/GratingPattern.hpp"
#include "patterns/GridBumpsPattern.hpp"
#include "patterns/HeightSlopePattern.hpp"

using namespace kf::patterns;

namespace {

constexpr double kRate = 48000;  // 48 samples a 1 ms frame

// Every line of the level is an even multiple of g = 1000 / periodFrames Hz (periodFrames odd;
// the motion's temporal frequencies chosen as even multiples of g), so the frames repeat every
// periodFrames frames and their spectrum is on bins of g. A harmonic at F > 500 Hz folds to
// |F - 1000 m|: an odd multiple of g for m odd (the folds from near 1, 3, 5... kHz, the first fold
// among them), so the odd bins hold only folded lines, the even ones the kept lines (and folds
// from near 2, 4... kHz, not separable). Returns the largest amplitude on the odd bins (level
// units) of one period of frames of levelAt(sample).
double largestFoldedLine(int periodFrames, const std::function<double(long)>& levelAt) {
  std::vector<double> frames(periodFrames);
  for (int f = 0; f < periodFrames; ++f) {
    double sum = 0;
    for (int s = 0; s < 48; ++s) sum += levelAt(48L * f + s);
    frames[f] = sum / 48;
  }
  double worst = 0;
  for (int bin = 1; 2 * bin < periodFrames; bin += 2) {
    std::complex<double> acc = 0, rotation = 1;
    const std::complex<double> step = std::polar(1.0, -2 * kPi * bin / periodFrames);
    for (double v : frames) acc += v * rotation, rotation *= step;
    worst = std::max(worst, 2 * std::abs(acc) / periodFrames);
  }
  return worst;
}

// The frame's travel ending at sample i of a motion x(i) = x0 + speed * i / kRate (mm).
Travel travelAt(double x0, double speed, long i) {
  const double to = x0 + speed * i / kRate, from = x0 + speed * (i - 48) / kRate;
  return Travel{from, to, speed > 0 ? 1 : -1, std::fabs(speed), 1e-3};
}

// The bar: a line left by the closed form is 2 |C_k| sinc <= (4 / pi) |C_k| of one harmonic past
// kStop >= kSharp, <= kNegligibleFold (PatternTravel.hpp); lines of harmonics k and k + L fold onto
// one bin (L the period in frames, >= 2001: their sum is within 1 % of the first), and the
// rounding of the double levels is ~1e-15. Before, sharp patterns between kStop = 64 and 2 * 64
// and past it kept every harmonic the box did (sinc ~ 0.64 at kStop): measured below.
constexpr double kBar = 1.01 * kNegligibleFold;

}  // namespace

TEST_CASE("folding: narrow 1D bumps and a hard-edged grating, kStop from 64 to past 128, and bumps2D") {
  // g = 1000 / 2001 Hz (2 s of frames); fundamentals 2a g.
  const int period = 2001;
  const double g = 1000.0 / period;
  struct Case {
    const char* name;
    double fundamentalHz;  // speed / spacing
    std::function<double(long)> levelAt;
  };
  BumpPattern bumps;  // 10 mm apart, 0.1 mm wide (omega 0.01: kSharp 2325)
  bumps.set(10, 0.1, false, 0);
  GratingPattern grating;  // 4 mm, duty 0.5, hard edge (kSharp 40528)
  grating.set(4, 0.5, 0, 0);
  auto bumpsAt = [&](double f1) {
    return [&bumps, f1](long i) { return bumps.level(travelAt(0.013, 10 * f1, i), true); };
  };
  auto gratingAt = [&](double f1) {
    return [&grating, f1](long i) { return grating.level(travelAt(0.013, 4 * f1, i), true); };
  };
  // kStop = 500 Hz / f1: bumps 100 (f1 = 10 g, 50 mm/s: the old blend) and 167 (6 g, 30 mm/s: the
  // old closed form); the grating 125 (8 g, 16 mm/s) and 250 (4 g, 8 mm/s).
  const std::vector<Case> cases{{"bumps 10 / 0.1 mm at 50 mm/s", 10 * g, bumpsAt(10 * g)},
                                {"bumps 10 / 0.1 mm at 30 mm/s", 6 * g, bumpsAt(6 * g)},
                                {"grating 4 mm, hard edge, at 16 mm/s", 8 * g, gratingAt(8 * g)},
                                {"grating 4 mm, hard edge, at 8 mm/s", 4 * g, gratingAt(4 * g)}};
  for (const Case& c : cases) {
    const double folded = largestFoldedLine(period, c.levelAt);
    INFO(c.name << " (kStop " << 500 / c.fundamentalHz << "): largest folded line " << folded);
    CHECK(folded < kBar);
  }
  // bumps2D on a 10 x 10 mm grid of 0.1 mm bumps, fx = 2 fy (26.6 degrees): fx = 4 g, fy = 2 g
  // (22 mm/s: Kx 146, Ky 207, past 128) and 8 g, 4 g (45 mm/s: Kx 73, Ky 104, the old blend).
  for (double fx : {4 * g, 8 * g}) {
    GridBumpsPattern grid;
    grid.set(10, 10, 0.1, 0, 0);
    const double vx = 10 * fx, vy = 5 * fx;
    const double folded = largestFoldedLine(period, [&](long i) {
      const Travel x = travelAt(0.013, vx, i);
      return grid.level(x, 0.031 + vy * (i - 48) / kRate, 0.031 + vy * i / kRate, true);
    });
    INFO("bumps2D at " << std::hypot(vx, vy) << " mm/s: largest folded line " << folded);
    CHECK(folded < kBar);
  }
}

TEST_CASE("folding: 1D bumps between kFull and 2 kFull (the new blend) stay below the bar") {
  // 4 mm / 2 mm bumps (omega 0.5: kSharp 329) at f1 = 4 g, g = 1000 / 4001 Hz: 4 mm/s, kStop 500,
  // h = 0.53: the closed form's harmonics past 500 fold, each below kNegligibleFold by kSharp's bound.
  // A guard of the blend region, not a proof of the change: the old rule (the closed form from
  // kStop 128) folds 2.1e-6 here, also below the bar (the cases above are the ones it failed).
  const int period = 4001;
  BumpPattern bumps;
  bumps.set(4, 2, false, 0);
  const double speed = 4 * 4 * 1000.0 / period;
  const double folded = largestFoldedLine(period, [&](long i) { return bumps.level(travelAt(0.013, speed, i), true); });
  INFO("largest folded line " << folded);
  CHECK(folded < kBar);
}

TEST_CASE("sharpness: the bounds kSharp is derived from hold for the harmonics the code has") {
  // RaisedCosineBump.hpp: from k omega >= 2 on, |climb C_k| <= 4 / (3 pi omega k^2) and
  // |height C_k| <= 2 / (3 pi omega^2 k^3); kSharp is where (4 / pi) of the bound is kNegligibleFold.
  for (double omega : {0.5, 0.2, 0.1, 1.0 / 16}) {
    RaisedCosineBump b;
    b.setWidth(omega);
    double worst = 0;
    for (int k = static_cast<int>(std::ceil(2 / omega)); k <= kMaxHarmonics; ++k) {
      for (int s : {1, -1})
        worst = std::max(worst, std::abs(b.climbHarmonics(s)[k - 1]) / (4 / (3 * kPi * omega * k * k)));
      worst = std::max(worst, std::abs(b.heightHarmonics()[k - 1]) / (2 / (3 * kPi * omega * omega * k * k * k)));
    }
    INFO("omega " << omega << ": largest |C_k| over its bound " << worst);
    CHECK(worst <= 1 + 1e-12);  // equal at k omega = 2 where cos(pi k omega / 2) = -1
    CHECK(worst > 0.5);         // the bound is near the coefficients, not loose by orders
    const double k = b.sharpHarmonic();
    CHECK(4 / kPi * 4 / (3 * kPi * omega * k * k) == Approx(kNegligibleFold).epsilon(1e-9));
  }
}

TEST_CASE("continuity: no step in the level as the speed crosses kStop = 64, kFull and 2 kFull") {
  // At each threshold speed v (kStop = 500 Hz / (v / period)), the level over a travel ending at a
  // fixed point at v (1 -+ 1e-9): a continuous rule moves by ~ its slope in v times 1e-9 v (< 1e-6
  // here). kStop = 128 is no threshold any more (the old blend ended there, continuously); kFull and
  // 2 kFull are the new ones, where a step would show.
  struct Case {
    const char* name;
    double period, kSharp;
    std::function<double(double)> levelAtSpeed;
  };
  BumpPattern bumps;
  bumps.set(10, 0.1, false, 0);
  RaisedCosineBump bump;  // the bumps' own (omega 0.01): its kSharp
  bump.setWidth(0.01);
  GratingPattern grating;
  grating.set(4, 0.5, 0, 0);
  DetentPattern detents;
  detents.set(3, 0.6, 0);
  const double end = 0.052;  // on the bump's climb, the grating's high part, a detent's ramp
  auto travel = [end](double v) { return Travel{end - v * 1e-3, end, 1, v, 1e-3}; };
  const std::vector<Case> cases{
      {"bumps", 10, bump.sharpHarmonic(), [&](double v) { return bumps.level(travel(v), true); }},
      {"grating", 4, grating.sharpHarmonic(), [&](double v) { return grating.level(travel(v), true); }},
      {"detents", 3, detents.sharpHarmonic(), [&](double v) { return detents.level(travel(v), true); }},
  };
  for (const Case& c : cases) {
    const double kFull = std::max<double>(kMaxHarmonics, c.kSharp);
    for (double kStop : {double(kMaxHarmonics), 2.0 * kMaxHarmonics, kFull, 2 * kFull}) {
      const double v = 500 * c.period / kStop;
      const double step = std::fabs(c.levelAtSpeed(v * (1 + 1e-9)) - c.levelAtSpeed(v * (1 - 1e-9)));
      INFO(c.name << " at kStop " << kStop << " (" << v << " mm/s): step " << step);
      CHECK(step < 1e-6);
    }
  }
  // bumps2D along 30 degrees on 10 x 10 mm, 0.1 mm bumps: Kx crosses 64, kSharp and twice it.
  GridBumpsPattern grid;
  grid.set(10, 10, 0.1, 0, 0);
  const double c = std::cos(kPi / 6), s = std::sin(kPi / 6);
  auto level2D = [&](double v) {
    return grid.level(Travel{end - c * v * 1e-3, end, 1, c * v, 1e-3}, 0.03 - s * v * 1e-3, 0.03, true);
  };
  for (double kx : {64.0, bump.sharpHarmonic(), 2 * bump.sharpHarmonic()}) {
    // Kx = 500 / (sqrt(fx) (sqrt(fx) + sqrt(fy))), f = v cos / 10, v sin / 10: v for the given Kx.
    const double v = 500 / (kx * std::sqrt(c / 10) * (std::sqrt(c / 10) + std::sqrt(s / 10)));
    const double step = std::fabs(level2D(v * (1 + 1e-9)) - level2D(v * (1 - 1e-9)));
    INFO("bumps2D at Kx " << kx << " (" << v << " mm/s): step " << step);
    CHECK(step < 1e-6);
  }
}
