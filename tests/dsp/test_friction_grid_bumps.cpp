// FrictionPattern's bumps2D (dsp/GridBumpsPattern) against its definition, written again here:
// h(x, y) = b(x) b(y), b a raised-cosine bump of width w from 0 in every spacing; the level is
// clip((h(now) - h(one frame ago)) / |travel| / (pi / w), 0, 1), held below 1e-4 mm of travel.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "FrictionPatternCore.hpp"

using namespace kf::patterns;

namespace {

constexpr double kLoN = 0.14, kHiN = 0.5;
constexpr double kSx = 4, kSy = 3, kW = 2;  // spacings and width (mm)

double bumpDef(double u, double spacing) {
  const double f = u / spacing - std::floor(u / spacing);
  return f * spacing < kW ? 0.5 * (1 - std::cos(2 * kPi * f * spacing / kW)) : 0.0;
}
double heightDef(double x, double y) { return bumpDef(x, kSx) * bumpDef(y, kSy); }

struct Path {
  std::vector<float> x, y;
};

// A line from (x0, y0) at speed mm/s along angle (rad), for seconds.
Path line(double x0, double y0, double angle, double speed, double seconds, double rate) {
  Path p;
  for (int i = 0; i < static_cast<int>(seconds * rate); ++i) {
    p.x.push_back(static_cast<float>(x0 + std::cos(angle) * speed * i / rate));
    p.y.push_back(static_cast<float>(y0 + std::sin(angle) * speed * i / rate));
  }
  return p;
}

std::vector<double> levels(const Path& p, double rate, bool antialias = true, double sx = kSx, double sy = kSy,
                           double w = kW) {
  FrictionPatternCore core(PatternKind::Bumps2D, rate);
  core.setForceRange({kLoN, kHiN});
  core.setAntialias(antialias);
  std::vector<float> force(p.x.size());
  for (size_t i = 0; i < p.x.size(); i += 64) {
    const int n = static_cast<int>(std::min<size_t>(64, p.x.size() - i));
    core.setParameters(sx, sy, w, p.x[i]);
    core.process(p.x.data() + i, 1, p.y.data() + i, 1, force.data() + i, n);
  }
  std::vector<double> out;
  for (float f : force) out.push_back((f - kLoN) / (kHiN - kLoN));
  return out;
}

// The definition's level per sample, from the float positions the core was given.
std::vector<double> definition(const Path& p, double rate) {
  const int n = static_cast<int>(std::lround(rate * 1e-3));
  std::vector<double> out;
  double held = 0;
  for (size_t i = 0; i < p.x.size(); ++i) {
    const size_t j = i >= static_cast<size_t>(n) ? i - n : 0;
    const double dx = double(p.x[i]) - p.x[j], dy = double(p.y[i]) - p.y[j], d = std::sqrt(dx * dx + dy * dy);
    if (d >= 1e-4)
      held = std::clamp((heightDef(p.x[i], p.y[i]) - heightDef(p.x[j], p.y[j])) / d / (kPi / kW), 0.0, 1.0);
    out.push_back(held);
  }
  return out;
}

// The force is a float: its level is exact to ~1e-7 N / 0.36 N; 1e-6 leaves room for the
// double rounding of the cosines.
constexpr double kTol = 1e-6;

}  // namespace

TEST_CASE("bumps2D: the definition along lines at angles, 44.1 to 192 kHz") {
  for (double rate : {44100.0, 48000.0, 96000.0, 192000.0}) {
    for (double angle : {0.0, 0.5, kPi / 4, 2.0, -2.5}) {
      const Path p = line(0.3, 0.7, angle, 60, 0.25, rate);
      const auto got = levels(p, rate), want = definition(p, rate);
      double worst = 0, top = 0;
      for (size_t i = 0; i < got.size(); ++i)
        worst = std::max(worst, std::fabs(got[i] - want[i])), top = std::max(top, got[i]);
      INFO("rate " << rate << " angle " << angle);
      CHECK(worst < kTol);
      CHECK(top > 0.2);  // the line meets bumps
    }
  }
}

TEST_CASE("bumps2D: along a diagonal through a bump's centre, climbing resists and descending is free") {
  // Bump centre at (1, 1); the diagonal x = y from (0.2, 0.2) to (1.8, 1.8) and back, 40 mm/s.
  const double rate = 48000, angle = kPi / 4, length = 1.6 * std::sqrt(2.0), speed = 40;
  const Path up = line(0.2, 0.2, angle, speed, length / speed, rate);
  const Path down = line(1.8, 1.8, angle + kPi, speed, length / speed, rate);
  // The minimum force is 0.14f, 1.7e-9 above 0.14 in level: "free" is a level below kFree.
  constexpr double kFree = 1e-8;
  for (const Path* p : {&up, &down}) {
    const auto got = levels(*p, rate);
    const size_t half = got.size() / 2;
    // First half (after the first frame): approaching the centre, climbing; after it (one frame
    // past the centre on): descending, the minimum force exactly.
    for (size_t i = 100; i < half - 10; ++i) REQUIRE(got[i] > kFree);
    for (size_t i = half + 60; i < got.size(); ++i) REQUIRE(got[i] < kFree);
  }
  // Across the centre along x the steepest slope is met: the full level, less the frame's mean of
  // sin(pi x) over 0.06 mm (60 mm/s, 1 ms): sinc(0.03 pi) = 1 - 1.5e-3.
  const auto across = levels(line(0.0, 1.0, 0.0, 60, 1.0 / 60, rate), rate);
  CHECK(*std::max_element(across.begin(), across.end()) == Approx(1.0).margin(2e-3));
}

TEST_CASE("bumps2D: the same force at every revisit of a circle, whatever came between") {
  const double rate = 48000;
  // 0.5 s a turn, radius 5 mm about (-4, 1.5): it starts at (1, 1.5) moving +y, on a bump's
  // steepest flank along y (its centre line in x): leaving forwards descends, arriving backwards
  // climbs (the full level).
  const int perTurn = 24000;
  Path p;
  auto circle = [&](int i) {
    const int k = ((i % perTurn) + perTurn) % perTurn;
    p.x.push_back(static_cast<float>(-4 + 5 * std::cos(2 * kPi * k / perTurn)));
    p.y.push_back(static_cast<float>(1.5 + 5 * std::sin(2 * kPi * k / perTurn)));
  };
  for (int i = 0; i < perTurn; ++i) circle(i);
  const Path away = line(-4 + 5 * std::cos(2 * kPi * (perTurn - 1) / perTurn), 1.5, 1.0, 70, 0.2, rate);
  p.x.insert(p.x.end(), away.x.begin(), away.x.end());  // elsewhere,
  p.y.insert(p.y.end(), away.y.begin(), away.y.end());
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
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::fabs(a[i] - b[i]));
  // x / spacing loses ~7200 / 3 * 2^-52 cycles (1e-12) far away: far below a float's step.
  CHECK(worst < kTol);
  CHECK(*std::max_element(b.begin(), b.end()) > 0.2);
}

TEST_CASE("bumps2D: NaN and inf positions hold, bad parameters keep the last good, raw is the slope at the point") {
  const double rate = 48000;
  Path p = line(0.3, 0.7, 0.5, 60, 0.2, rate);
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
  const auto want = definition(holding, rate);
  double worst = 0;
  for (size_t i = 0; i < held.size(); ++i) worst = std::max(worst, std::fabs(held[i] - want[i]));
  CHECK(worst < kTol);
  for (size_t i = 0; i < at; ++i) REQUIRE(held[i] == clean[i]);
  // Bad parameters from the start: the defaults (spacings 1 mm, width 0.5 mm, as bumps'), as the
  // core given them.
  Path q = line(0.3, 0.7, 0.5, 60, 0.2, rate);
  const auto defaults = levels(q, rate, true, 1, 1, 0.5);
  const auto nans = levels(q, rate, true, std::nan(""), -1, HUGE_VAL);
  for (size_t i = 0; i < q.x.size(); ++i) REQUIRE(nans[i] == defaults[i]);
  // Raw (antialias 0): the directional slope at the current point, here ~ the frame mean (60 mm/s
  // is 0.06 mm a frame; the mean and point differ by < 0.06 mm * max curvature (2 pi^2 / w^2 over
  // pi / w) = 0.06 * pi = 0.19 at most).
  const auto raw = levels(p, rate, false);
  worst = 0;
  for (size_t i = 48; i < raw.size(); ++i) worst = std::max(worst, std::fabs(raw[i] - clean[i]));
  CHECK(worst < 0.19);
  CHECK(worst > 0.0);
}

TEST_CASE("bumps2D: a change of spacing while moving keeps the bumps' phase under the puck, on both axes") {
  // 60 mm/s at 30 degrees, at (48.5, 37) at sample 4800 (a block start: 0.5 mm up a bump's flank
  // in x, on its centre line in y) where the spacings go 4 x 3 -> 4.4 x 3.3 mm. Kept at the anchor
  // (x: the block's first position; y: the last y before it), a cell coordinate after the change
  // is (u - anchor) / new spacing + anchor / old spacing. Anchored at the origin instead, the puck
  // would jump from 0.5 to 0.1 mm into its bump in x and from 1.0 to 0.7 mm in y.
  const double rate = 48000;
  const size_t change = 4800;
  const Path p = line(48.5 - 6 * std::cos(kPi / 6), 34, kPi / 6, 60, 0.2, rate);
  FrictionPatternCore core(PatternKind::Bumps2D, rate);
  core.setForceRange({kLoN, kHiN});
  std::vector<float> force(p.x.size());
  for (size_t i = 0; i < p.x.size(); i += 64) {
    const bool later = i >= change;
    core.setParameters(later ? 4.4 : 4.0, later ? 3.3 : 3.0, 2.0, p.x[i]);
    core.process(p.x.data() + i, 1, p.y.data() + i, 1, force.data() + i, 64);
  }
  const double ax = p.x[change], ay = p.y[change - 1];
  auto bumpAt = [](double cycles, double spacing) {
    const double d = (cycles - std::floor(cycles)) * spacing;  // mm into the cell
    return d < kW ? 0.5 * (1 - std::cos(2 * kPi * d / kW)) : 0.0;
  };
  auto h = [&](double x, double y, bool later) {
    if (!later) return bumpAt(x / 4.0, 4.0) * bumpAt(y / 3.0, 3.0);
    return bumpAt((x - ax) / 4.4 + ax / 4.0, 4.4) * bumpAt((y - ay) / 3.3 + ay / 3.0, 3.3);
  };
  double worst = 0, jump = 0;
  for (size_t i = 48; i < force.size(); ++i) {
    const double dx = double(p.x[i]) - p.x[i - 48], dy = double(p.y[i]) - p.y[i - 48];
    const double d = std::sqrt(dx * dx + dy * dy), later = i >= change;
    const double want =
        std::clamp((h(p.x[i], p.y[i], later) - h(p.x[i - 48], p.y[i - 48], later)) / d / (kPi / kW), 0.0, 1.0);
    worst = std::max(worst, std::fabs((force[i] - kLoN) / (kHiN - kLoN) - want));
    if (i == change) jump = std::fabs(force[i] - force[i - 1]) / (kHiN - kLoN);
  }
  CHECK(worst < kTol);
  CHECK(jump < 0.2);  // the zoom about the puck: 0.5 -> 0.55 mm into the bump, level 0.87 -> 0.75
}
