// SpeedGovernor: force from speed against its definition, on both axes, at the limits and for
// non-finite speeds.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "SpeedGovernor.hpp"

using kf::governorForceN;
using kf::GovernorSettings;

TEST_CASE("governor: the resting force up to the target, rising by the gain above it, capped") {
  const GovernorSettings g{80.0, 0.01, 0.14, 1.4};
  CHECK(governorForceN(0, 0, g) == 0.14f);
  CHECK(governorForceN(80, 0, g) == 0.14f);
  CHECK(governorForceN(-80, 0, g) == 0.14f);  // either direction
  CHECK(governorForceN(100, 0, g) == Approx(0.14 + 0.2));
  CHECK(governorForceN(-100, 0, g) == Approx(0.34));
  CHECK(governorForceN(80 + 126, 0, g) == Approx(1.4));
  CHECK(governorForceN(1e6, 0, g) == 1.4f);
  // The speed on the surface is the length of (vx, vy): 60 and 80 make 100 mm/s.
  CHECK(governorForceN(60, 80, g) == Approx(0.34));
  CHECK(governorForceN(-60, -80, g) == Approx(0.34));
  CHECK(governorForceN(0, 90, g) == Approx(0.24));
}

TEST_CASE("governor: a non-finite speed gives the resting force") {
  const GovernorSettings g{10.0, 0.1, 0.2, 1.0};
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  CHECK(governorForceN(nan, 0, g) == 0.2f);
  CHECK(governorForceN(0, nan, g) == 0.2f);
  CHECK(governorForceN(inf, 0, g) == 0.2f);
  CHECK(governorForceN(0, -inf, g) == 0.2f);
}

TEST_CASE("governor: the block follows the per-sample force, held and audio-rate speeds") {
  const GovernorSettings g{50.0, 0.005, 0.14, 1.4};
  float vx[64], vy[64], out[64];
  for (int i = 0; i < 64; ++i) vx[i] = 5.f * i, vy[i] = -2.f * i;
  kf::governorBlock(vx, 1, vy, 1, g, out, 64);
  for (int i = 0; i < 64; ++i) CHECK(out[i] == governorForceN(vx[i], vy[i], g));
  kf::governorBlock(vx + 30, 0, vy + 30, 0, g, out, 64);
  for (int i = 0; i < 64; ++i) CHECK(out[i] == governorForceN(vx[30], vy[30], g));
  kf::governorBlock(vx, 1, vy, 1, g, vx, 64);  // over its own input
  for (int i = 0; i < 64; ++i) CHECK(vx[i] == governorForceN(5.f * i, -2.f * i, g));
}
