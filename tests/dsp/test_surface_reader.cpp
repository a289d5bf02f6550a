// SurfaceReader: a 2D matrix read at (x, y) mm against a reference written apart from it (tap
// weights in double over the zero-padded matrix), on the hard cases: edges, rotated paths, huge
// coordinates, NaN and Inf, paths sampled at 44.1 to 192 kHz.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include "SurfaceReader.hpp"

using kf::Interpolation;
using kf::readSurface;
using kf::SurfaceLayout;
using kf::SurfaceView;

namespace {

const Interpolation kAll[] = {Interpolation::None, Interpolation::Linear, Interpolation::Cubic};
const double kPi = 3.14159265358979323846;

struct Matrix {
  int width, height;
  std::vector<float> data;
  SurfaceView view() const { return {data.data(), width, height}; }
  double at(long c, long r) const {  // zero-padded
    return c < 0 || c >= width || r < 0 || r >= height ? 0.0 : data[static_cast<size_t>(r * width + c)];
  }
};

// Values with no structure the interpolators could exploit: a hash of the index in [-1, 1].
Matrix noiseMatrix(int width, int height) {
  Matrix m{width, height, std::vector<float>(static_cast<size_t>(width * height))};
  uint32_t state = 12345;
  for (auto& v : m.data) {
    state = state * 1664525u + 1013904223u;
    v = static_cast<float>(state >> 8) / static_cast<float>(1 << 23) - 1.f;
  }
  return m;
}

// A quadratic in (column, row): the bicubic (Catmull-Rom) kernel reproduces it exactly where all
// 16 taps are inside, so it is the surface's own value at any point, any path.
double quadratic(double c, double r) { return 0.01 * c * c - 0.02 * c * r + 0.015 * r * r + 0.3 * c - 0.2 * r + 1.0; }

Matrix quadraticMatrix(int width, int height) {
  Matrix m{width, height, std::vector<float>(static_cast<size_t>(width * height))};
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) m.data[static_cast<size_t>(r * width + c)] = static_cast<float>(quadratic(c, r));
  return m;
}

// Tap weights of each mode at fraction t, for taps at whole part - 1 .. whole part + 2.
void weights(Interpolation mode, double t, double w[4]) {
  if (mode == Interpolation::None) {
    w[0] = 0, w[1] = 1, w[2] = 0, w[3] = 0;
  } else if (mode == Interpolation::Linear) {
    w[0] = 0, w[1] = 1 - t, w[2] = t, w[3] = 0;
  } else {  // Catmull-Rom in its matrix form
    w[0] = 0.5 * (-t + 2 * t * t - t * t * t);
    w[1] = 0.5 * (2 - 5 * t * t + 3 * t * t * t);
    w[2] = 0.5 * (t + 4 * t * t - 3 * t * t * t);
    w[3] = 0.5 * (-t * t + t * t * t);
  }
}

// The definition: outside (-1, size) in either axis 0; else the weighted padded taps.
double reference(const Matrix& m, double c, double r, Interpolation mode) {
  if (!(c > -1 && c < m.width && r > -1 && r < m.height)) return 0.0;
  const long i = static_cast<long>(std::floor(c)), j = static_cast<long>(std::floor(r));
  double wx[4], wy[4];
  weights(mode, c - i, wx);
  weights(mode, r - j, wy);
  double sum = 0;
  for (int b = 0; b < 4; ++b)
    for (int a = 0; a < 4; ++a) sum += wy[b] * wx[a] * m.at(i - 1 + a, j - 1 + b);
  return sum;
}

// Float kernels against the double reference: values within [-1, 1], at most 16 taps with weights
// summing to 1 in absolute value below 1.6 (Catmull-Rom's overshoot, squared), each product rounded
// in float (2^-24 relative): measured worst 5.7e-7; 2e-6 leaves a margin without hiding a wrong tap
// (a tap off by one changes the result by ~0.1 on the noise matrix).
constexpr double kTolerance = 2e-6;

}  // namespace

TEST_CASE("surface: whole indices read the matrix row-major in every mode") {
  const Matrix m = noiseMatrix(7, 5);
  for (auto mode : kAll)
    for (int r = 0; r < m.height; ++r)
      for (int c = 0; c < m.width; ++c) CHECK(readSurface(m.view(), c, r, mode) == m.data[r * 7 + c]);
}

TEST_CASE("surface: the reference at random points, edges and corners included") {
  const Matrix m = noiseMatrix(9, 6);
  uint32_t state = 7;
  auto uniform = [&](double lo, double hi) {
    state = state * 1664525u + 1013904223u;
    return lo + (hi - lo) * (state >> 8) / double(1 << 24);
  };
  double worst = 0;
  for (auto mode : kAll)
    for (int k = 0; k < 20000; ++k) {
      // Up to two samples beyond every border: the fades and the zeros outside.
      const double c = uniform(-2.5, m.width + 1.5), r = uniform(-2.5, m.height + 1.5);
      const double got = readSurface(m.view(), c, r, mode);
      const double want = reference(m, c, r, mode);
      worst = std::max(worst, std::abs(got - want));
      if (!(c > -1 && c < m.width && r > -1 && r < m.height)) REQUIRE(got == 0.f);  // exactly 0 outside
    }
  INFO("worst difference " << worst);
  CHECK(worst < kTolerance);
}

TEST_CASE("surface: the borders fade in and out as SpatialReader's, exactly 0 a sample outside") {
  const Matrix m = noiseMatrix(6, 6);
  for (auto mode : kAll)
    for (double d : {-1.0, -1.0 + 1e-9, -0.5, 5.5, 6.0 - 1e-9, 6.0}) {
      const double inside = 2.25;
      const bool zero = !(d > -1 && d < 6);
      if (zero) {  // at -1 and at the size: every tap padded, exactly 0
        CHECK(readSurface(m.view(), d, inside, mode) == 0.f);
        CHECK(readSurface(m.view(), inside, d, mode) == 0.f);
      }
      CHECK(std::abs(readSurface(m.view(), d, inside, mode) - reference(m, d, inside, mode)) < kTolerance);
      CHECK(std::abs(readSurface(m.view(), inside, d, mode) - reference(m, inside, d, mode)) < kTolerance);
    }
  // A one-sample and a one-row matrix: the fades on both sides of the single sample.
  const Matrix one{1, 1, {0.75f}};
  CHECK(readSurface(one.view(), 0, 0, Interpolation::Cubic) == 0.75f);
  CHECK(std::abs(readSurface(one.view(), 0.5, -0.5, Interpolation::Linear) - 0.75 * 0.25) < kTolerance);
  const Matrix row = noiseMatrix(8, 1);
  CHECK(std::abs(readSurface(row.view(), 3.3, 0.4, Interpolation::Cubic) -
                 reference(row, 3.3, 0.4, Interpolation::Cubic)) < kTolerance);
}

TEST_CASE("surface: a rotated path reads a quadratic surface exactly, at every angle") {
  const Matrix m = quadraticMatrix(64, 48);
  const SurfaceLayout layout{-10.0, 5.0, 2.0, 1.5};  // origin (-10, 5) mm, 2 and 1.5 samples per mm
  // Lines through the centre at 0..360 degrees, staying two samples inside every border.
  const double cx = -10.0 + 32 / 2.0, cy = 5.0 + 24 / 1.5, radius = 9.0;
  double worst = 0;
  for (int degrees = 0; degrees < 360; degrees += 15) {
    const double a = degrees * kPi / 180;
    std::vector<float> x(200), y(200), out(200);
    for (int k = 0; k < 200; ++k) {
      x[k] = static_cast<float>(cx + radius * (k / 100.0 - 1) * std::cos(a));
      y[k] = static_cast<float>(cy + radius * (k / 100.0 - 1) * std::sin(a));
    }
    kf::readSurfaceBlock(m.view(), x.data(), 1, y.data(), 1, layout, Interpolation::Cubic, out.data(), 200);
    for (int k = 0; k < 200; ++k) {
      const double c = (x[k] - layout.originXMm) * layout.samplesPerMmX;
      const double r = (y[k] - layout.originYMm) * layout.samplesPerMmY;
      worst = std::max(worst, std::abs(out[k] - quadratic(c, r)) / std::abs(quadratic(c, r)));
      // The rotation changes nothing: the reference at the same point.
      REQUIRE(std::abs(out[k] - reference(m, c, r, Interpolation::Cubic)) < 1e-5 * std::abs(quadratic(c, r)));
    }
  }
  INFO("worst relative difference " << worst);
  CHECK(worst < 1e-5);  // float rounding of values up to ~50 (measured 2e-7)
}

TEST_CASE("surface: far from the origin the indices stay exact in double") {
  const Matrix m = noiseMatrix(16, 16);
  // Positions 1e6..8e6 mm from the table's zero, half a mm apart (exact floats there): in double the
  // index of each is exact; a float index (x - origin, times samplesPerMm, rounded to 24 bits of
  // ~1e7) would be off by up to a sample.
  for (double originMm : {1.0e6, -3.0e6, 8.0e6}) {
    const SurfaceLayout layout{originMm, -originMm, 1.7, 2.3};
    std::vector<float> x(64), y(64), out(64);
    for (int k = 0; k < 64; ++k) {
      x[k] = static_cast<float>(originMm + 0.5 * (k % 16));
      y[k] = static_cast<float>(-originMm + 0.5 * (k / 4));
    }
    kf::readSurfaceBlock(m.view(), x.data(), 1, y.data(), 1, layout, Interpolation::Cubic, out.data(), 64);
    for (int k = 0; k < 64; ++k) {
      const double c = (static_cast<double>(x[k]) - originMm) * 1.7, r = (static_cast<double>(y[k]) + originMm) * 2.3;
      REQUIRE(out[k] == readSurface(m.view(), c, r, Interpolation::Cubic));
      REQUIRE(std::abs(out[k] - reference(m, c, r, Interpolation::Cubic)) < kTolerance);
    }
  }
  // Indices far outside, in either direction, are silence, without overflow.
  for (auto mode : kAll)
    for (double huge : {1e300, -1e300, 9.3e18, -9.3e18, 1e12}) {
      CHECK(readSurface(m.view(), huge, 3, mode) == 0.f);
      CHECK(readSurface(m.view(), 3, huge, mode) == 0.f);
    }
}

TEST_CASE("surface: NaN, Inf and empty matrices give silence") {
  const Matrix m = noiseMatrix(4, 4);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (auto mode : kAll) {
    for (double bad : {nan, inf, -inf}) {
      CHECK(readSurface(m.view(), bad, 1.5, mode) == 0.f);
      CHECK(readSurface(m.view(), 1.5, bad, mode) == 0.f);
    }
    CHECK(readSurface(SurfaceView{}, 0, 0, mode) == 0.f);
    CHECK(readSurface(SurfaceView{m.data.data(), 0, 4}, 0, 0, mode) == 0.f);
    CHECK(readSurface(SurfaceView{m.data.data(), 4, 0}, 0, 0, mode) == 0.f);
  }
  // Through the block reader: a NaN or Inf position (as FrictionMouseIn never gives, but a user's
  // arithmetic may) is silence, the samples around it are read as usual.
  const float fnan = std::numeric_limits<float>::quiet_NaN(), finf = std::numeric_limits<float>::infinity();
  float x[4] = {1.f, fnan, 1.f, finf}, y[4] = {1.f, 1.f, finf, 1.f}, out[4];
  kf::readSurfaceBlock(m.view(), x, 1, y, 1, SurfaceLayout{}, Interpolation::Linear, out, 4);
  CHECK(out[0] == m.data[5]);
  CHECK(out[1] == 0.f);
  CHECK(out[2] == 0.f);
  CHECK(out[3] == 0.f);
}

TEST_CASE("surface: a circle sampled at 44.1 to 192 kHz, held and audio-rate positions") {
  const Matrix m = noiseMatrix(40, 30);
  const SurfaceLayout layout{0.0, 0.0, 4.0, 3.0};
  for (double rate : {44100.0, 48000.0, 96000.0, 192000.0}) {
    // 0.05 s of a 3 mm circle at 0.5 turns per 0.05 s around (5, 5) mm: the same path whatever
    // the rate, read in blocks of 64 as the UGen does.
    const int n = static_cast<int>(0.05 * rate);
    std::vector<float> x(n), y(n), out(n);
    for (int k = 0; k < n; ++k) {
      const double a = 2 * kPi * 10.0 * k / rate;
      x[k] = static_cast<float>(5 + 3 * std::cos(a));
      y[k] = static_cast<float>(5 + 3 * std::sin(a));
    }
    for (auto mode : kAll)
      for (int start = 0; start < n; start += 64) {
        const int block = std::min(64, n - start);
        kf::readSurfaceBlock(m.view(), x.data() + start, 1, y.data() + start, 1, layout, mode, out.data() + start,
                             block);
        for (int k = start; k < start + block; ++k)
          REQUIRE(std::abs(out[k] - reference(m, x[k] * 4.0, y[k] * 3.0, mode)) < kTolerance);
      }
    // A position held over a block (control rate): every sample reads the first position.
    kf::readSurfaceBlock(m.view(), x.data() + 7, 0, y.data() + 7, 0, layout, Interpolation::Cubic, out.data(), 64);
    for (int k = 0; k < 64; ++k) REQUIRE(out[k] == readSurface(m.view(), x[7] * 4.0, y[7] * 3.0, Interpolation::Cubic));
  }
}

TEST_CASE("surface: the block reader may write over its position input") {
  const Matrix m = noiseMatrix(10, 10);
  std::vector<float> x(64), y(64, 4.5f), want(64);
  for (int k = 0; k < 64; ++k) x[k] = 0.1f * k;
  kf::readSurfaceBlock(m.view(), x.data(), 1, y.data(), 1, SurfaceLayout{}, Interpolation::Cubic, want.data(), 64);
  kf::readSurfaceBlock(m.view(), x.data(), 1, y.data(), 1, SurfaceLayout{}, Interpolation::Cubic, x.data(), 64);
  CHECK(x == want);
}
