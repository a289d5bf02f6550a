// SpatialReader: index arithmetic, the three interpolators, and what they read at the borders.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "CorePathScope.hpp"
#include "SpatialReader.hpp"

using kf::Interpolation;
using kf::readSpatial;
using kf::SignalView;

namespace {

// Catmull-Rom in its matrix form, written independently of the kernel under test.
double catmullRom(double t, double y0, double y1, double y2, double y3) {
  return 0.5 *
         (2 * y1 + (-y0 + y2) * t + (2 * y0 - 5 * y1 + 4 * y2 - y3) * t * t + (-y0 + 3 * y1 - 3 * y2 + y3) * t * t * t);
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
    for (double p : {-5.0, 0.0, 3.3, 1e6})
      CHECK(readSpatial(s, 0, kf::spatialIndex(p, 0, 0), Interpolation::Cubic) == v[0]);
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

// The UGen's path: readSpatialBlock must give readSpatial's values bit for bit, whatever the
// mode, channel count, position rate, block length, and wherever the positions fall.
TEST_CASE("the block reader equals the per-sample reader bit for bit") {
  EACH_CORE_PATH();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (int channels : {1, 2, 3}) {
    const int frames = 37;
    std::vector<float> v(frames * channels);
    for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(std::sin(0.7 * i) + 0.01 * i);
    SignalView s{v.data(), frames, channels};
    // Positions (mm, origin 2, 4 samples/mm): inside, at and across both borders, far outside,
    // non-finite, in runs long enough for whole inside pieces and mixed pieces.
    std::vector<float> pos;
    for (int i = 0; i < 300; ++i) pos.push_back(static_cast<float>(2.0 + 0.03 * i));          // inside
    for (int i = 0; i < 200; ++i) pos.push_back(static_cast<float>(1.5 + 0.0137 * i));        // index -2 .. 9
    for (int i = 0; i < 200; ++i) pos.push_back(static_cast<float>(2.0 + 8.6 + 0.0071 * i));  // 34.4 .. 40
    for (float x : {nan, inf, -inf, 1e30, -1e30, 2.0 - 0.25, 2.0 - 0.2499, 2.0 + 9.25, 2.0 + 9.2499})
      pos.push_back(static_cast<float>(x));
    for (int i = 0; i < 100; ++i) pos.push_back(static_cast<float>(2.0 + 0.09 * i));
    for (auto mode : kAll) {
      for (int blockLen : {1, 3, 64, 65, 128, 1000}) {
        std::vector<std::vector<float>> out(channels, std::vector<float>(pos.size(), -99.f));
        std::vector<float*> outs;
        for (auto& o : out) outs.push_back(o.data());
        for (size_t done = 0; done < pos.size(); done += blockLen) {
          const int len = static_cast<int>(std::min<size_t>(blockLen, pos.size() - done));
          std::vector<float*> at;
          for (float* o : outs) at.push_back(o + done);
          kf::readSpatialBlock(s, pos.data() + done, 1, 2.0, 4.0, mode, at.data(), len);
        }
        for (int c = 0; c < channels; ++c)
          for (size_t i = 0; i < pos.size(); ++i) {
            const float want = readSpatial(s, c, kf::spatialIndex(pos[i], 2.0, 4.0), mode);
            INFO("channels " << channels << " mode " << int(mode) << " block " << blockLen << " i " << i);
            REQUIRE(std::memcmp(&out[c][i], &want, sizeof(float)) == 0);
          }
      }
      // A position held over the block (control rate): every output is the one read.
      for (float p : {2.0f + 3.3f, 1.8f, 2.0f + 9.2f, 100.f}) {
        std::vector<std::vector<float>> out(channels, std::vector<float>(70, -99.f));
        std::vector<float*> outs;
        for (auto& o : out) outs.push_back(o.data());
        kf::readSpatialBlock(s, &p, 0, 2.0, 4.0, mode, outs.data(), 70);
        for (int c = 0; c < channels; ++c)
          for (float o : out[c]) REQUIRE(o == readSpatial(s, c, kf::spatialIndex(p, 2.0, 4.0), mode));
      }
    }
  }
}

TEST_CASE("the block reader may write over its position input") {
  EACH_CORE_PATH();
  std::vector<float> v(100);
  for (int i = 0; i < 100; ++i) v[i] = static_cast<float>(i % 9) - 4.f;
  SignalView s{v.data(), 100, 1};
  for (auto mode : kAll) {
    std::vector<float> pos(200);
    for (int i = 0; i < 200; ++i) pos[i] = static_cast<float>(-1.0 + 0.55 * i);
    std::vector<float> want(200);
    for (int i = 0; i < 200; ++i) want[i] = readSpatial(s, 0, kf::spatialIndex(pos[i], 0.0, 1.0), mode);
    float* out[1] = {pos.data()};
    kf::readSpatialBlock(s, pos.data(), 1, 0.0, 1.0, mode, out, 200);
    for (int i = 0; i < 200; ++i) REQUIRE(pos[i] == want[i]);
  }
}

TEST_CASE("the block reader: empty signals are silent, indices at 1e7 stay exact") {
  EACH_CORE_PATH();
  std::vector<float> pos(10, 1.f), o(10, -1.f);
  float* out[1] = {o.data()};
  for (auto mode : kAll) {
    kf::readSpatialBlock(SignalView{nullptr, 8, 1}, pos.data(), 1, 0.0, 1.0, mode, out, 10);
    for (float x : o) REQUIRE(x == 0.f);
  }
  // A ramp of 1e7 + 64 samples read at index 1e7 + 0.25: linear gives the exact value there.
  std::vector<float> big(10000064);
  for (size_t i = 0; i < big.size(); ++i) big[i] = static_cast<float>(i % 16);
  SignalView s{big.data(), static_cast<int64_t>(big.size()), 1};
  const float p = 2500.0f;  // 2500 mm x 4000 samples/mm = 1e7 exactly
  float q[1] = {p};
  kf::readSpatialBlock(s, q, 1, 0.0, 4000.0, Interpolation::Linear, out, 1);
  CHECK(o[0] == static_cast<float>(10000000 % 16));
  q[0] = p;
  kf::readSpatialBlock(s, q, 1, -0.0000625, 4000.0, Interpolation::Linear, out, 1);  // + 0.25 sample
  CHECK(o[0] == Approx(10000000 % 16 + 0.25).margin(1e-6));
}
