// SpatialReader: index arithmetic, the three interpolators, and what they read at the borders.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include "SpatialReader.hpp"

using kf::Interpolation;
using kf::readSpatial;
using kf::SignalView;

namespace {

// Catmull-Rom in its matrix form, written independently of the kernel under test.
double catmullRom(double t, double y0, double y1, double y2, double y3) {
  return 0.5 * (2 * y1 + (-y0 + y2) * t + (2 * y0 - 5 * y1 + 4 * y2 - y3) * t * t +
                (-y0 + 3 * y1 - 3 * y2 + y3) * t * t * t);
}

std::vector<float> ramp(int n) {
  std::vector<float> v(n);
  for (int i = 0; i < n; ++i) v[i] = static_cast<float>(i + 1);
  return v;
}

const Interpolation kAll[] = {Interpolation::None, Interpolation::Linear, Interpolation::Cubic};

}  // namespace

TEST_CASE("interpolation codes follow BufRd") {
  CHECK(kf::interpolationFromCode(1) == Interpolation::None);
  CHECK(kf::interpolationFromCode(2) == Interpolation::Linear);
  CHECK(kf::interpolationFromCode(4) == Interpolation::Cubic);
  CHECK(kf::interpolationFromCode(3) == Interpolation::Cubic);
  CHECK(kf::interpolationFromCode(-7) == Interpolation::Cubic);
}

TEST_CASE("whole indices read the samples in every mode") {
  auto v = ramp(16);
  SignalView s{v.data(), 16, 1};
  for (auto mode : kAll)
    for (int i = 0; i < 16; ++i) CHECK(readSpatial(s, 0, i, mode) == v[i]);
}

TEST_CASE("none truncates, linear interpolates between neighbours") {
  auto v = ramp(8);
  SignalView s{v.data(), 8, 1};
  CHECK(readSpatial(s, 0, 2.75, Interpolation::None) == 3.f);
  CHECK(readSpatial(s, 0, 2.75, Interpolation::Linear) == Approx(3.75f));
}

TEST_CASE("cubic is BufRd's 4-point Hermite kernel") {
  std::vector<float> v = {0.3f, -0.8f, 0.1f, 0.9f, -0.4f, 0.25f};
  SignalView s{v.data(), 6, 1};
  for (double t : {0.0, 0.125, 0.5, 0.7, 0.999}) {
    double want = catmullRom(t, v[1], v[2], v[3], v[4]);
    CHECK(readSpatial(s, 0, 2.0 + t, Interpolation::Cubic) == Approx(want).margin(1e-6));
  }
}

TEST_CASE("cubic reproduces a quadratic exactly inside the signal") {
  std::vector<float> v(32);
  for (int i = 0; i < 32; ++i) v[i] = static_cast<float>(0.01 * i * i - 0.2 * i + 1);
  SignalView s{v.data(), 32, 1};
  for (double x = 1.0; x < 30.0; x += 0.37)
    CHECK(readSpatial(s, 0, x, Interpolation::Cubic) == Approx(0.01 * x * x - 0.2 * x + 1).margin(2e-5));
}

TEST_CASE("beyond the first and last sample the interpolators read zeros") {
  std::vector<float> v = {1.f, 1.f, 1.f, 1.f};
  SignalView s{v.data(), 4, 1};
  SECTION("linear fades over one sample at each border") {
    CHECK(readSpatial(s, 0, -0.25, Interpolation::Linear) == Approx(0.75f));
    CHECK(readSpatial(s, 0, 3.5, Interpolation::Linear) == Approx(0.5f));
  }
  SECTION("cubic uses zero taps: the value at -0.5 is the kernel on (0, 0, 1, 1)") {
    CHECK(readSpatial(s, 0, -0.5, Interpolation::Cubic) == Approx(catmullRom(0.5, 0, 0, 1, 1)));
    CHECK(readSpatial(s, 0, 3.5, Interpolation::Cubic) == Approx(catmullRom(0.5, 1, 1, 0, 0)));
  }
  SECTION("no wrapping: the far border is not read near the near border") {
    std::vector<float> w = {0.f, 0.f, 0.f, 5.f};
    SignalView t{w.data(), 4, 1};
    for (auto mode : kAll) CHECK(readSpatial(t, 0, -0.5, mode) == 0.f);
  }
  SECTION("exactly silent a whole sample or more outside, and continuous at the edges") {
    for (auto mode : kAll) {
      for (double x : {-1.0, -1.5, -1e9, 4.0, 4.25, 1e12, 1e300, -1e300}) CHECK(readSpatial(s, 0, x, mode) == 0.f);
    }
    for (auto mode : {Interpolation::Linear, Interpolation::Cubic}) {
      CHECK(std::fabs(readSpatial(s, 0, -1.0 + 1e-9, mode)) < 1e-6f);
      CHECK(std::fabs(readSpatial(s, 0, 4.0 - 1e-9, mode)) < 1e-6f);
    }
  }
}

TEST_CASE("NaN, Inf and empty signals give silence") {
  auto v = ramp(8);
  SignalView s{v.data(), 8, 1};
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (auto mode : kAll) {
    CHECK(readSpatial(s, 0, nan, mode) == 0.f);
    CHECK(readSpatial(s, 0, inf, mode) == 0.f);
    CHECK(readSpatial(s, 0, -inf, mode) == 0.f);
    CHECK(readSpatial(SignalView{nullptr, 8, 1}, 0, 2.0, mode) == 0.f);
    CHECK(readSpatial(SignalView{v.data(), 0, 1}, 0, 0.0, mode) == 0.f);
    CHECK(readSpatial(s, 0, kf::spatialIndex(nan, 0, 1), mode) == 0.f);
    CHECK(readSpatial(s, 0, kf::spatialIndex(1.0, 0, inf), mode) == 0.f);
  }
}

TEST_CASE("a single-sample signal") {
  std::vector<float> v = {0.5f};
  SignalView s{v.data(), 1, 1};
  CHECK(readSpatial(s, 0, 0.0, Interpolation::Cubic) == 0.5f);
  CHECK(readSpatial(s, 0, 0.5, Interpolation::Linear) == Approx(0.25f));
  CHECK(readSpatial(s, 0, 1.0, Interpolation::Cubic) == 0.f);
}

TEST_CASE("multichannel buffers are read interleaved, each channel on its own") {
  std::vector<float> v = {1, -1, 2, -2, 3, -3, 4, -4, 5, -5};
  SignalView s{v.data(), 5, 2};
  for (auto mode : kAll)
    for (double x : {0.0, 1.5, 2.25, 3.9, -0.5, 4.5}) CHECK(readSpatial(s, 1, x, mode) == -readSpatial(s, 0, x, mode));
  CHECK(readSpatial(s, 1, 2.0, Interpolation::Cubic) == -3.f);
}

TEST_CASE("samplesPerMm: zero, negative and huge are well defined") {
  auto v = ramp(64);
  SignalView s{v.data(), 64, 1};
  SECTION("zero holds the first sample wherever the puck is") {
    for (double p : {-5.0, 0.0, 3.3, 1e6}) CHECK(readSpatial(s, 0, kf::spatialIndex(p, 0, 0), Interpolation::Cubic) == v[0]);
  }
  SECTION("negative lays the signal out to the left of the origin") {
    CHECK(kf::spatialIndex(-2.0, 0.0, -4.0) == 8.0);
    CHECK(readSpatial(s, 0, kf::spatialIndex(-2.0, 0.0, -4.0), Interpolation::Linear) == v[8]);
    CHECK(readSpatial(s, 0, kf::spatialIndex(2.0, 0.0, -4.0), Interpolation::Linear) == 0.f);
  }
  SECTION("1e6 samples per mm: sub-micrometre positions still index exactly") {
    CHECK(kf::spatialIndex(0.0000125, 0.0, 1e6) == Approx(12.5).epsilon(1e-12));
    CHECK(readSpatial(s, 0, kf::spatialIndex(0.0000125, 0.0, 1e6), Interpolation::Linear) == Approx(13.5f));
    CHECK(readSpatial(s, 0, kf::spatialIndex(1.0, 0.0, 1e6), Interpolation::Cubic) == 0.f);
  }
}

TEST_CASE("a position far from the origin keeps its index exact in double") {
  // Both inputs are floats, as UGen inputs are; their difference and product are exact in
  // double, where a float phase at index 1e7 could not hold fractions of a sample.
  const float originMm = 2500.0f, positionMm = 2500.000244140625f;  // one float ulp above
  const double index = kf::spatialIndex(positionMm, originMm, 4000.0);
  CHECK(index == 0.9765625);
  const float bigFloatPhase = static_cast<float>(1e7 + 0.25);
  CHECK(static_cast<double>(bigFloatPhase) != 1e7 + 0.25);  // what BufRd's float phase loses
  CHECK(kf::spatialIndex(2500.0f + 0.25, 0.0, 4000.0) == 1e7 + 1000.0);
}
