// FrictionPattern's bumps2D (dsp/patterns/GridBumpsPattern) against its definition, written again here:
// h(x, y) = b(x) b(y), b a raised-cosine bump of width w from 0 in every spacing; the climb
// counted per axis, level = (|ux| (pi / wx) c_x(x) b(y) + |uy| b(x) (pi / wy) c_y(y)) / (pi / w)
// (c: the one-axis bump's climb in the sign of that velocity component, over its steepest slope).
// Slow, the level is each factor's mean over its axis's travel in the frame; with no travel, the
// rule at the point in the last direction.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <vector>

#include "ForceFrameSpectrum.hpp"
#include "PlanePaths.hpp"
#include "patterns/FrictionPatternCore.hpp"

using namespace kf::patterns;

namespace {

// The tests' alias measure, shared with bench/patterns_bench.cpp.
using kf::spectrum::frames;
using kf::spectrum::largestNonDcAmplitude;

constexpr double kLoN = 0.14, kHiN = 0.5;

// A grid: spacings, width (mm) and the phase of each axis in cycles (0 unless the spacing changed).
struct Grid {
  double sx = 4, sy = 3, w = 2, phaseX = 0, phaseY = 0;
};

// One axis: u in cycles, omega the width in cycles.
double bumpAt(double u, double omega) {
  const double f = u - std::floor(u);
  return f < omega ? 0.5 * (1 - std::cos(2 * kPi * f / omega)) : 0.0;
}
// The climb (height units) met going from u0 to u1: b rises on [k, k + omega / 2] and does not
// rise on [k + omega / 2, k + 1]; summed over those pieces in the order of travel.
double ascent(double u0, double u1, double omega) {
  std::vector<double> at{u0};
  for (double k = std::floor(std::min(u0, u1)); k <= std::max(u0, u1); k += 1)
    for (double b : {k, k + omega / 2})
      if (b > std::min(u0, u1) && b < std::max(u0, u1)) at.push_back(b);
  std::sort(at.begin() + 1, at.end());
  if (u1 < u0) std::reverse(at.begin() + 1, at.end());
  at.push_back(u1);
  double sum = 0;
  for (size_t i = 1; i < at.size(); ++i) sum += std::max(0.0, bumpAt(at[i], omega) - bumpAt(at[i - 1], omega));
  return sum;
}
// The mean of b over [u0, u1] from its integral B(u) = floor(u) omega / 2 + G(frac(u)).
double bumpMean(double u0, double u1, double omega) {
  if (std::fabs(u1 - u0) < 1e-9) return bumpAt(u1, omega);
  auto B = [omega](double u) {
    const double f = u - std::floor(u);
    const double g = f < omega ? f / 2 - omega / (4 * kPi) * std::sin(2 * kPi * f / omega) : omega / 2;
    return std::floor(u) * omega / 2 + g;
  };
  return (B(u1) - B(u0)) / (u1 - u0);
}

// The definition, slow (every factor its box mean): (ascent_x mean b_y + mean b_x ascent_y) / d
// over the steepest slope, for the frame's travel (x0, y0) -> (x1, y1).
double boxRule(const Grid& g, double x0, double y0, double x1, double y1) {
  const double d = std::hypot(x1 - x0, y1 - y0), ox = g.w / g.sx, oy = g.w / g.sy;
  const double ux0 = x0 / g.sx + g.phaseX, ux1 = x1 / g.sx + g.phaseX;
  const double uy0 = y0 / g.sy + g.phaseY, uy1 = y1 / g.sy + g.phaseY;
  const double climb = ascent(ux0, ux1, ox) * bumpMean(uy0, uy1, oy) + bumpMean(ux0, ux1, ox) * ascent(uy0, uy1, oy);
  return std::clamp(climb / d / (kPi / g.w), 0.0, 1.0);
}

// The definition at the point (x, y) moving with signs (sx, sy) and unit direction (ux, uy).
double pointRule(const Grid& g, double x, double y, double ux, double uy, int sx, int sy) {
  const double ox = g.w / g.sx, oy = g.w / g.sy, fx = x / g.sx - std::floor(x / g.sx),
               fy = y / g.sy - std::floor(y / g.sy);
  const double cx = fx < ox ? std::max(0.0, sx * std::sin(2 * kPi * fx / ox)) : 0.0;
  const double cy = fy < oy ? std::max(0.0, sy * std::sin(2 * kPi * fy / oy)) : 0.0;
  return std::fabs(ux) * cx * bumpAt(y / g.sy, oy) + std::fabs(uy) * bumpAt(x / g.sx, ox) * cy;
}

// The directional slope u . grad h over pi / w, not rectified.
double directionalSlope(const Grid& g, double x, double y, double ux, double uy) {
  const double ox = g.w / g.sx, oy = g.w / g.sy, fx = x / g.sx - std::floor(x / g.sx),
               fy = y / g.sy - std::floor(y / g.sy);
  const double sx = fx < ox ? std::sin(2 * kPi * fx / ox) : 0.0, sy = fy < oy ? std::sin(2 * kPi * fy / oy) : 0.0;
  return ux * sx * bumpAt(y / g.sy, oy) + uy * bumpAt(x / g.sx, ox) * sy;
}

using kf::testpaths::line;
using kf::testpaths::Path;

std::vector<float> forces(const Path& p, double rate, bool antialias, const Grid& g = Grid{}) {
  FrictionPatternCore core(PatternKind::Bumps2D, rate);
  core.setForceRange({kLoN, kHiN});
  core.setAntialias(antialias);
  std::vector<float> force(p.x.size());
  for (size_t i = 0; i < p.x.size(); i += 64) {
    const int n = static_cast<int>(std::min<size_t>(64, p.x.size() - i));
    core.setParameters(g.sx, g.sy, g.w, p.x[i]);
    core.process(p.x.data() + i, 1, p.y.data() + i, 1, force.data() + i, n);
  }
  return force;
}

// The 1D bumps' level (spacing, width mm) along positions x.
std::vector<double> levels1D(const std::vector<float>& x, double rate, double spacing, double width, bool antialias) {
  FrictionPatternCore bumps(PatternKind::Bumps, rate);
  bumps.setForceRange({kLoN, kHiN});
  bumps.setAntialias(antialias);
  std::vector<float> f(x.size());
  for (size_t i = 0; i < f.size(); i += 64) {
    bumps.setParameters(spacing, width, 0, x[i]);
    bumps.process(x.data() + i, 1, nullptr, 1, f.data() + i, int(std::min<size_t>(64, f.size() - i)));
  }
  std::vector<double> out;
  for (float v : f) out.push_back((v - kLoN) / (kHiN - kLoN));
  return out;
}

std::vector<double> levels(const Path& p, double rate, bool antialias = true, const Grid& g = Grid{}) {
  std::vector<double> out;
  for (float f : forces(p, rate, antialias, g)) out.push_back((f - kLoN) / (kHiN - kLoN));
  return out;
}

// A definition per sample over the frame's travel (from one frame ago, the first position
// before the start); with no travel, the rule at the point in the last direction (none at first: 0).
template <class Rule>
std::vector<double> perFrame(const Path& p, double rate, Rule rule, const Grid& g = Grid{}) {
  const size_t n = static_cast<size_t>(std::lround(rate * 1e-3));
  std::vector<double> out;
  double ux = 0, uy = 0;
  int sx = 1, sy = 1;
  for (size_t i = 0; i < p.x.size(); ++i) {
    const size_t j = i >= n ? i - n : 0;
    const double dx = double(p.x[i]) - p.x[j], dy = double(p.y[i]) - p.y[j], d = std::hypot(dx, dy);
    if (d > 0) {
      out.push_back(rule(double(p.x[j]), double(p.y[j]), double(p.x[i]), double(p.y[i])));
      ux = dx / d, uy = dy / d;
      if (dx != 0) sx = dx > 0 ? 1 : -1;
      if (dy != 0) sy = dy > 0 ? 1 : -1;
    } else {
      out.push_back(pointRule(g, p.x[i], p.y[i], ux, uy, sx, sy));
    }
  }
  return out;
}

std::vector<double> slowDefinition(const Path& p, double rate, const Grid& g = Grid{}) {
  return perFrame(
      p, rate, [&](double x0, double y0, double x1, double y1) { return boxRule(g, x0, y0, x1, y1); }, g);
}

double worstDifference(const std::vector<double>& a, const std::vector<double>& b, size_t from = 0) {
  double worst = 0;
  for (size_t i = from; i < a.size(); ++i) worst = std::max(worst, std::fabs(a[i] - b[i]));
  return worst;
}

// The force is a float: its level is exact to ~1e-7 N / 0.36 N; 1e-6 leaves room for the
// double rounding of the cosines.
constexpr double kTol = 1e-6;

// 1 ms frame means of a level's force (ForceFrameSpectrum.hpp's frames).
std::vector<double> frames(const std::vector<double>& level, size_t from) {
  std::vector<float> f;
  for (double l : level) f.push_back(static_cast<float>(kLoN + (kHiN - kLoN) * l));
  return frames(f, from);
}

}  // namespace

TEST_CASE("bumps2D: slow lines at angles, out and back, are the rule's mean over the travel, 44.1 to 192 kHz") {
  // 1 mm/s over 4 x 3 mm: every axis's first harmonic not kept is >= 1040 (Ky at 2.0 rad), past
  // twice the bumps' kSharp (329 for omega 0.5 along x, 285 for 2/3 along y; PatternTravel.hpp), so
  // the level is the closed form: each factor's mean over its travel.
  for (double rate : {44100.0, 48000.0, 96000.0, 192000.0}) {
    for (double angle : {0.0, kPi / 2, kPi / 6, kPi / 4, 2.0, -2.5, kPi}) {
      Path p = line(0.3, 0.7, angle, 1, 0.6, rate);
      p.append(line(p.x.back(), p.y.back(), angle + kPi, 1, 0.6, rate));  // the way back
      const auto got = levels(p, rate), want = slowDefinition(p, rate);
      INFO("rate " << rate << " angle " << angle);
      CHECK(worstDifference(got, want) < kTol);
      CHECK(*std::max_element(got.begin(), got.end()) > 0.1);  // meets bumps (along y: b(0.3 mm) = 0.21)
    }
  }
}

TEST_CASE(
    "bumps2D: raw, the rule at the point: the directional slope through a bump's centre on the diagonal, "
    "the climbing axis where the other descends") {
  const double rate = 48000, speed = 40;
  const Grid g;
  // Per sample, from the frame's travel in float positions (its direction is exact to ~1e-5).
  auto check = [&](const Path& p) {
    const auto got = levels(p, rate, false);
    const auto rule = perFrame(p, rate, [&](double x0, double y0, double x1, double y1) {
      const double d = std::hypot(x1 - x0, y1 - y0);
      return pointRule(g, x1, y1, (x1 - x0) / d, (y1 - y0) / d, x1 > x0 ? 1 : -1, y1 > y0 ? 1 : -1);
    });
    const auto slope = perFrame(p, rate, [&](double x0, double y0, double x1, double y1) {
      const double d = std::hypot(x1 - x0, y1 - y0);
      return std::clamp(directionalSlope(g, x1, y1, (x1 - x0) / d, (y1 - y0) / d), 0.0, 1.0);
    });
    double above = 0;
    for (size_t i = 48; i < got.size(); ++i) above = std::max(above, got[i] - slope[i]);
    return std::array<double, 3>{worstDifference(got, rule, 48), worstDifference(got, slope, 48), above};
  };
  // The bump's centre is at (1, 1): the diagonals through it, both ways.
  for (int s : {1, -1}) {
    const Path p =
        line(1 - s * 0.8, 1 - s * 0.8, s > 0 ? kPi / 4 : -3 * kPi / 4, speed, 1.6 * std::sqrt(2.0) / speed, rate);
    const auto [worst, directional, above] = check(p);
    CHECK(worst < kTol);
    CHECK(directional < kTol);  // the directional slope, rectified
  }
  // From (0.2, 0.9) along (1, -1): x climbs its bump (to 1) while y descends it (0.9 -> 0.1).
  const Path p = line(0.2, 0.9, -kPi / 4, speed, 0.6 * std::sqrt(2.0) / speed, rate);
  const auto [worst, directional, above] = check(p);
  CHECK(worst < kTol);
  CHECK(above > 0.1);  // counts the x climb the directional slope nets against y's descent
  // The rule never passes 1 (GridBumpsPattern.hpp), so the code's clamp never bites: its raw level
  // on a 200 x 200 grid of one cell, 24 directions, widths equal and not (the width clamped to a
  // 1 mm spacing), is the rule written here, unclamped, and its top is in (0.99, 1].
  for (const Grid& grid : {Grid{}, Grid{1, 3, 2}}) {
    GridBumpsPattern pattern;
    pattern.set(grid.sx, grid.sy, grid.w, 0, 0);
    const double wx = std::min(grid.w, grid.sx), wy = std::min(grid.w, grid.sy), wMin = std::min(wx, wy);
    double top = 0, worstRule = 0;
    for (int a = 0; a < 24; ++a) {
      const double ux = std::cos(2 * kPi * a / 24), uy = std::sin(2 * kPi * a / 24);
      for (int i = 0; i < 200; ++i)
        for (int j = 0; j < 200; ++j) {
          const double x = wx * i / 200, y = wy * j / 200, ox = wx / grid.sx, oy = wy / grid.sy;
          const double cx = std::max(0.0, (ux > 0 ? 1 : -1) * std::sin(2 * kPi * x / wx));
          const double cy = std::max(0.0, (uy > 0 ? 1 : -1) * std::sin(2 * kPi * y / wy));
          const double rule = std::fabs(ux) * cx * bumpAt(y / grid.sy, oy) * wMin / wx +
                              std::fabs(uy) * bumpAt(x / grid.sx, ox) * cy * wMin / wy;
          // A frame's travel of 0.01 mm ending at (x, y) along (ux, uy): 10 mm/s.
          const double got =
              pattern.level(Travel{x - 0.01 * ux, x, ux > 0 ? 1 : -1, 10, 1e-3}, y - 0.01 * uy, y, false);
          worstRule = std::max(worstRule, std::fabs(got - rule));
          top = std::max(top, got);
        }
    }
    INFO("spacings " << grid.sx << " x " << grid.sy << ": top " << top << ", worst against the rule " << worstRule);
    CHECK(worstRule < kTol);
    CHECK(top <= 1.0);
    CHECK(top > 0.99);
  }
}

TEST_CASE("bumps2D: along an axis the level is the 1D bumps' times the other axis's bump, at every speed") {
  // 5 mm/s: the closed form; 20: the crossfade (Kx = 500 Hz / 5 Hz = 100); 60: the series; 300
  // and 3000: a few harmonics, then the mean. Both ways along x (y = 1.3 mm) and along y (x = 0.7), from
  // -1 mm or 7.2 mm: each run climbs a bump.
  const double rate = 48000;
  for (double speed : {5.0, 20.0, 60.0, 300.0, 3000.0}) {
    for (int s : {1, -1}) {
      for (bool alongX : {true, false}) {
        const double spacing = alongX ? 4 : 3, across = alongX ? 1.3 : 0.7;
        const double seconds = std::min(0.3, 8 / speed);
        const Path axis = line(s > 0 ? -1 : 7.2, 0, s > 0 ? 0 : kPi, speed, seconds, rate);
        Path p;
        p.x = axis.x;
        p.y.assign(axis.x.size(), float(across));
        if (!alongX) std::swap(p.x, p.y);
        FrictionPatternCore bumps(PatternKind::Bumps, rate);
        bumps.setForceRange({kLoN, kHiN});
        std::vector<float> f1(axis.x.size());
        for (size_t i = 0; i < f1.size(); i += 64) {
          bumps.setParameters(spacing, 2, 0, axis.x[i]);
          bumps.process(axis.x.data() + i, 1, nullptr, 1, f1.data() + i, int(std::min<size_t>(64, f1.size() - i)));
        }
        const double b = bumpAt(across / (alongX ? 3 : 4), 2 / (alongX ? 3.0 : 4.0));
        const auto got = levels(p, rate);
        double worst = 0, top = 0;
        // From the first travel on (before it bumps2D has no direction, 1D's is +1).
        for (size_t i = 1; i < got.size(); ++i) {
          worst = std::max(worst, std::fabs(got[i] - (f1[i] - kLoN) / (kHiN - kLoN) * b));
          top = std::max(top, got[i]);
        }
        INFO(speed << " mm/s, direction " << s << (alongX ? " along x" : " along y"));
        CHECK(worst < kTol);
        CHECK(top > 0.05);
      }
    }
  }
  // A width clamped on one axis only: 4 x 1 mm, width 2 (wy = 1 mm). Along x on the bumps' centre
  // line in y (b = 1) the level is the 1D bumps' (4 mm, width 2) times min(wx, wy) / wx = 1/2.
  for (double speed : {5.0, 60.0}) {
    const Path axis = line(-1, 0, 0, speed, std::min(0.3, 8 / speed), rate);
    Path p{axis.x, std::vector<float>(axis.x.size(), 0.5f)};
    const auto got = levels(p, rate, true, Grid{4, 1, 2}), bumps = levels1D(axis.x, rate, 4, 2, true);
    double worst = 0;
    for (size_t i = 1; i < got.size(); ++i) worst = std::max(worst, std::fabs(got[i] - 0.5 * bumps[i]));
    INFO(speed << " mm/s along x on a 4 x 1 mm grid: worst " << worst);
    CHECK(worst < kTol);
    CHECK(*std::max_element(bumps.begin(), bumps.end()) > 0.9);
  }
}

TEST_CASE("bumps2D: creeping and reversing on a flank, the 1D bumps times the bump across") {
  // Below 0.1 mm/s (1e-4 mm a frame) the level was held: a puck creeping up a flank at 0.05 mm/s
  // kept 0 (the 1D bumps climb 0.59 -> 0.81 of the way), and one reversing there stepped. Now the
  // direction is held, not the level: the rule at the point, as 1D. Along x at y = 1.3 mm.
  const double rate = 48000, across = 1.3, b = bumpAt(across / 3, 2 / 3.0);
  const int n = 96000;
  Path creep, reverse;
  for (int i = 0; i < n; ++i) {
    creep.x.push_back(static_cast<float>(0.2 + 0.05 * i / rate));  // 0.05 mm/s for 2 s
    // 0.6 + 0.5 sin(pi t): turns at 1.1 mm (descending flank) and 0.1 mm (climbing flank).
    reverse.x.push_back(static_cast<float>(0.6 + 0.5 * std::sin(kPi * i / rate)));
  }
  for (Path* p : {&creep, &reverse}) p->y.assign(n, static_cast<float>(across));
  for (bool antialias : {true, false}) {
    for (const Path* p : {&creep, &reverse}) {
      const auto got = levels(*p, rate, antialias), bumps = levels1D(p->x, rate, 4, 2, antialias);
      double worst = 0, lo = 1, hi = 0;
      for (size_t i = 1; i < got.size(); ++i) {  // from the first travel on
        worst = std::max(worst, std::fabs(got[i] - b * bumps[i]));
        lo = std::min(lo, got[i]), hi = std::max(hi, got[i]);
      }
      INFO((p == &creep ? "creeping" : "reversing")
           << (antialias ? "" : ", raw") << ": worst " << worst << ", level " << lo << " to " << hi);
      CHECK(worst < kTol);
      CHECK(hi - lo > 0.2 * b);  // it moves over the flank
    }
  }
}

TEST_CASE("bumps2D: a 0.2 mm grid at 300 mm/s has no alias in the force frames, at 5 mm/s it is rendered in full") {
  // 300 mm/s over 0.2 mm is 1500 Hz along an axis (1299 and 750 Hz at 30 degrees), past the
  // frames' 500 Hz Nyquist frequency on every axis that moves: each axis's first harmonic not kept
  // is < 1, so every moving factor is its mean and a still one its value: the frames are constant
  // but for float rounding (the force's, 0.36 N * 2^-24 ~ 2e-8 N, and at 30 degrees that of the
  // direction from float positions, ~1e-5 of a ~0.04 N level): the stated level is 1e-6 N
  // (measured 0 along the axes, 4e-10 N at 30 degrees). Without anti-aliasing the frames alias
  // (measured 0.0156 N along an axis, 0.0129 N at 30 degrees), and so they did rendered as before
  // (the rise over the frame's 0.3 mm travel over its length, a box 1.5 cells long: measured 0.0031
  // and 0.0020 N); > 0.005 N and > 0.001 N show this test sees those aliases.
  const double rate = 48000;
  const Grid fine{0.2, 0.2, 0.1};
  struct Line {
    const char* name;
    double x0, y0, angle;
  };
  // Along x on the bumps' centre line in y (b(y) = 1), along y likewise, and at 30 degrees.
  for (const Line& l : {Line{"along x", 0.013, 0.05, 0.0}, Line{"along y", 0.05, 0.013, kPi / 2},
                        Line{"at 30 degrees", 0.013, 0.031, kPi / 6}}) {
    const Path fast = line(l.x0, l.y0, l.angle, 300, 0.3, rate);
    const double on = largestNonDcAmplitude(frames(forces(fast, rate, true, fine), 480));
    const double off = largestNonDcAmplitude(frames(forces(fast, rate, false, fine), 480));
    // The box-only rendering: (h(now) - h(a frame ago)) / travel over the steepest slope.
    const auto boxOnly = perFrame(fast, rate, [&](double x0, double y0, double x1, double y1) {
      auto h = [&](double x, double y) { return bumpAt(x / 0.2, 0.5) * bumpAt(y / 0.2, 0.5); };
      return std::clamp((h(x1, y1) - h(x0, y0)) / std::hypot(x1 - x0, y1 - y0) / (kPi / 0.1), 0.0, 1.0);
    });
    const double box = largestNonDcAmplitude(frames(boxOnly, 480));
    INFO(l.name << ": alias with " << on << " N, without " << off << " N, box only " << box << " N");
    CHECK(on < 1e-6);
    CHECK(off > 0.005);
    CHECK(box > 0.001);
    // 5 mm/s over 0.2 mm is 25 Hz on the axis (x: 21.7 Hz, y: 12.5 Hz at 30 degrees): a factor
    // keeps its harmonics up to the 10th to 20th. The level swings from free to the rule's own
    // peak on the path (raw) but for the spline kernel's rounding of it (1/20 of a cell): within
    // 15 % of the peak (measured 94 % along an axis, 87 % at 30 degrees).
    const Path slow = line(l.x0, l.y0, l.angle, 5, 0.2, rate);
    const auto s = levels(slow, rate, true, fine), raw = levels(slow, rate, false, fine);
    const auto [lo, hi] = std::minmax_element(s.begin() + 48, s.end());
    const double peak = *std::max_element(raw.begin() + 48, raw.end());
    INFO("at 5 mm/s: " << *lo << " to " << *hi << ", the rule's peak " << peak);
    CHECK(*lo < 1e-3);
    CHECK(*hi > 0.85 * peak);
    CHECK(peak > 0.5);
  }
}

TEST_CASE("bumps2D: the same force at every revisit of a circle, whatever came between") {
  const double rate = 48000;
  // 0.5 s a turn, radius 5 mm about (-4, 1.5): it starts at (1, 1.5) moving +y, on a bump's
  // steepest flank along y (its centre line in x): leaving forwards descends, arriving backwards
  // climbs (near the full level).
  const int perTurn = 24000;
  Path p;
  auto circle = [&](int i) {
    const int k = ((i % perTurn) + perTurn) % perTurn;
    p.x.push_back(static_cast<float>(-4 + 5 * std::cos(2 * kPi * k / perTurn)));
    p.y.push_back(static_cast<float>(1.5 + 5 * std::sin(2 * kPi * k / perTurn)));
  };
  for (int i = 0; i < perTurn; ++i) circle(i);
  p.append(line(-4 + 5 * std::cos(2 * kPi * (perTurn - 1) / perTurn), 1.5, 1.0, 70, 0.2, rate));  // elsewhere,
  for (int i = 0; i <= perTurn / 4; ++i) circle(perTurn / 4 - i);  // then backwards to the start
  const size_t second = p.x.size();
  for (int i = 0; i < perTurn; ++i) circle(i);
  const auto got = levels(p, rate);
  // One frame after the start of each turn the frames hold the same positions: the same level.
  size_t differ = 0;
  for (int i = 48; i < perTurn; ++i) differ += got[i] != got[second + i];
  CHECK(differ == 0);
  CHECK(got[second - 1] > 0.9);  // arriving, it climbed
  CHECK(*std::max_element(got.begin(), got.begin() + perTurn) > 0.2);
}

TEST_CASE("bumps2D: far from the origin, the same as near it (float positions exact there)") {
  // Steps of 2^-9 mm per sample (93.75 mm/s at 48 kHz) along a diagonal: exact floats both near 0
  // and near 7200 mm (a multiple of both spacings; floats there step by 2^-10 mm).
  const double rate = 48000, offset = 7200, step = 1.0 / 512;
  Path nearPath, farPath;
  for (int i = 0; i < 9600; ++i) {
    nearPath.x.push_back(static_cast<float>(0.5 + step * i)), nearPath.y.push_back(static_cast<float>(0.25 + step * i));
    farPath.x.push_back(static_cast<float>(offset + 0.5 + step * i));
    farPath.y.push_back(static_cast<float>(offset + 0.25 + step * i));
  }
  REQUIRE(double(farPath.x.back()) - offset == double(nearPath.x.back()));
  const auto a = levels(nearPath, rate), b = levels(farPath, rate);
  // x / spacing loses ~7200 / 3 * 2^-52 cycles (1e-12) far away: far below a float's step.
  CHECK(worstDifference(a, b) < kTol);
  CHECK(*std::max_element(b.begin(), b.end()) > 0.2);
}

TEST_CASE("bumps2D: NaN and inf positions hold, bad parameters keep the last good, raw is the rule at the point") {
  const double rate = 48000;
  Path p = line(0.3, 0.7, 0.5, 1, 1.0, rate);  // 1 mm/s: the closed form (as the slow lines')
  const auto clean = levels(p, rate);
  Path bad = p;
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN(), kInf = std::numeric_limits<float>::infinity();
  // Bad positions where the line climbs hardest (a level held there is not 0 by chance).
  const size_t at = std::max_element(clean.begin() + 1000, clean.end() - 1000) - clean.begin();
  REQUIRE(clean[at] > 0.2);
  for (size_t i = at; i < at + 10; ++i) bad.x[i] = kNaN, bad.y[i] = (i % 2 ? kInf : -kInf);
  const auto held = levels(bad, rate);
  // The definition on the path with each bad coordinate held at its last finite value.
  Path holding = p;
  for (size_t i = at; i < at + 10; ++i) holding.x[i] = p.x[at - 1], holding.y[i] = p.y[at - 1];
  CHECK(worstDifference(held, slowDefinition(holding, rate)) < kTol);
  for (size_t i = 0; i < at; ++i) REQUIRE(held[i] == clean[i]);
  // Bad parameters from the start: the defaults (spacings 1 mm, width 0.5 mm, as bumps'), as the
  // core given them.
  const auto defaults = levels(p, rate, true, Grid{1, 1, 0.5});
  const auto nans = levels(p, rate, true, Grid{std::nan(""), -1, HUGE_VAL});
  for (size_t i = 0; i < p.x.size(); ++i) REQUIRE(nans[i] == defaults[i]);
  // Raw (antialias 0): the rule at the current point, in the frame's direction per axis.
  const auto raw = levels(p, rate, false);
  const auto point = perFrame(p, rate, [&](double x0, double y0, double x1, double y1) {
    const double d = std::hypot(x1 - x0, y1 - y0);
    return pointRule(Grid{}, x1, y1, (x1 - x0) / d, (y1 - y0) / d, x1 > x0 ? 1 : -1, y1 > y0 ? 1 : -1);
  });
  CHECK(worstDifference(raw, point, 48) < kTol);
  CHECK(worstDifference(raw, clean, 48) > 0.0);
}

TEST_CASE("bumps2D: a change of spacing while moving keeps the bumps' phase under the puck, on both axes") {
  // 1 mm/s at 30 degrees (the closed form: Kx >= 1353, past twice kSharp, 690 on 4.4 mm), at
  // (48.5, 37) at sample 4800 (a block start: 0.5 mm up a bump's flank
  // in x, on its centre line in y) where the spacings go 4 x 3 -> 4.4 x 3.3 mm. Kept at the anchor
  // (x: the block's first position; y: the last y before it), a cell coordinate after the change
  // is (u - anchor) / new spacing + anchor / old spacing. Anchored at the origin instead, the puck
  // would jump from 0.5 to 0.1 mm into its bump in x and from 1.0 to 0.7 mm in y.
  const double rate = 48000;
  const size_t change = 4800;
  const Path p = line(48.5 - 0.1 * std::cos(kPi / 6), 37 - 0.05, kPi / 6, 1, 0.2, rate);
  FrictionPatternCore core(PatternKind::Bumps2D, rate);
  core.setForceRange({kLoN, kHiN});
  std::vector<float> force(p.x.size());
  for (size_t i = 0; i < p.x.size(); i += 64) {
    const bool later = i >= change;
    core.setParameters(later ? 4.4 : 4.0, later ? 3.3 : 3.0, 2.0, p.x[i]);
    core.process(p.x.data() + i, 1, p.y.data() + i, 1, force.data() + i, 64);
  }
  const double ax = p.x[change], ay = p.y[change - 1];
  const Grid before{4, 3, 2}, after{4.4, 3.3, 2, ax / 4.0 - ax / 4.4, ay / 3.0 - ay / 3.3};
  double worst = 0, jump = 0;
  for (size_t i = 48; i < force.size(); ++i) {
    const double want = boxRule(i >= change ? after : before, p.x[i - 48], p.y[i - 48], p.x[i], p.y[i]);
    worst = std::max(worst, std::fabs((force[i] - kLoN) / (kHiN - kLoN) - want));
    if (i == change) jump = std::fabs(force[i] - force[i - 1]) / (kHiN - kLoN);
  }
  CHECK(worst < kTol);
  CHECK(jump < 0.2);  // the zoom about the puck: 0.5 -> 0.55 mm into the bump
}

namespace {

// The amplitude (N) at frequencyHz of 1 ms frames (frame rate 1 kHz), by a DFT at that frequency
// under a 4-term Blackman-Harris window (sidelobes below -92 dB: a 0.1 N line 8 Hz away or more
// leaks < 3e-6 N into it at 1 s of frames).
double amplitudeAt(const std::vector<double>& v, double frequencyHz) {
  std::complex<double> acc = 0;
  double wsum = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    const double p = 2 * kPi * i / v.size();
    const double w = 0.35875 - 0.48829 * std::cos(p) + 0.14128 * std::cos(2 * p) - 0.01168 * std::cos(3 * p);
    acc += v[i] * w * std::polar(1.0, -2 * kPi * frequencyHz * i / 1000.0);
    wsum += w;
  }
  return 2 * std::abs(acc) / wsum;
}

}  // namespace

TEST_CASE("bumps2D: no component of the grid folds into the frames when both axes move, 20 to 120 mm/s") {
  // Component (m, n) of the 0.2 mm grid moved at (vx, vy) is a line at |m fx + n fy| Hz (fx = vx /
  // 0.2 mm). Every one above the frames' 500 Hz folds to |F - 1000 round(F / 1000)|; each must be
  // gone (the axes share the Nyquist frequency, Kx fx + Ky fy = 500 Hz). Lines folding within 8 Hz
  // of a kept one (|m| < Kx, |n| < Ky) are not separable and skipped. What is left there: float
  // rounding (~2e-8 N) and the window's leakage from the kept lines (< 3e-6 N): the stated level is
  // 1e-5 N (measured 8e-8 N at worst). Each axis given the whole 500 Hz instead (Kx = 500 / fx)
  // left 1.4e-4 to 9.3e-3 N (measured, every case failed).
  const double rate = 48000;
  const Grid fine{0.2, 0.2, 0.1};
  for (double speed : {20.0, 60.0, 120.0}) {
    for (double angle : {kPi / 6, 1.2}) {
      const Path p = line(0.013, 0.031, angle, speed, 1.05, rate);
      const auto fr = frames(forces(p, rate, true, fine), 2400);
      std::vector<double> d(fr.begin(), fr.begin() + 1000);
      double mean = 0;
      for (double a : d) mean += a / d.size();
      for (double& a : d) a -= mean;
      const double fx = speed * std::fabs(std::cos(angle)) / 0.2, fy = speed * std::fabs(std::sin(angle)) / 0.2;
      const double kx = 500 / (std::sqrt(fx) * (std::sqrt(fx) + std::sqrt(fy))),
                   ky = 500 / (std::sqrt(fy) * (std::sqrt(fx) + std::sqrt(fy)));
      std::vector<double> kept{0.0};
      for (int m = -kMaxHarmonics; m <= kMaxHarmonics; ++m)
        for (int n = 0; n <= kMaxHarmonics; ++n)
          if (std::abs(m) < kx && n < ky) kept.push_back(std::fabs(m * fx + n * fy));
      double worst = 0;
      for (int m = -kMaxHarmonics; m <= kMaxHarmonics; ++m) {
        for (int n = 0; n <= kMaxHarmonics; ++n) {
          const double f = std::fabs(m * fx + n * fy);
          if (f <= 500) continue;
          const double folded = std::fabs(f - 1000 * std::round(f / 1000));
          if (std::any_of(kept.begin(), kept.end(), [&](double k) { return std::fabs(folded - k) < 8; })) continue;
          worst = std::max(worst, amplitudeAt(d, folded));
        }
      }
      INFO(speed << " mm/s at " << angle << " rad: worst folded line " << worst << " N");
      CHECK(worst < 1e-5);
    }
  }
}
