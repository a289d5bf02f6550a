// Counts per mm from a measured stroke, CPI as a starting value, and the profile file.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>

#include "mouse/MouseProfile.hpp"

using namespace kf;

TEST_CASE("count size from a measured stroke, either direction, CPI as a starting value", "[profile]") {
  // 100 mm along the ruler, 4762 counts: the paper's 0.021 mm.
  CHECK(countMmFromStroke(4762, 100.0) == Approx(0.0209996));
  CHECK(countMmFromStroke(-4762, 100.0) == countMmFromStroke(4762, 100.0));
  CHECK(std::isnan(countMmFromStroke(0, 100.0)));  // the mouse saw nothing: no answer
  CHECK(std::isnan(countMmFromStroke(100, 0.0)));
  CHECK(std::isnan(countMmFromStroke(100, -5.0)));
  CHECK(std::isnan(countMmFromStroke(100, NAN)));
  CHECK(countMmFromCpi(1000) == Approx(0.0254));
  CHECK(countMmFromCpi(1200) == Approx(0.021166667));
  CHECK(std::isnan(countMmFromCpi(0)));
}

TEST_CASE("mouse profile: written, read back, applied to the spec", "[profile]") {
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/mouse-profile.txt";
  MouseProfile p;
  p.name = "Genius Gila Gaming Mouse";
  p.vendorId = 0x0458;
  p.productId = 0x0138;
  p.surface = "steel sheet, matte";
  p.cpi = 1200;
  p.countMmX = countMmFromStroke(4731, 100.0);
  p.countMmY = countMmFromStroke(-4690, 100.0);
  p.updateRateHz = 500;
  std::string error;
  REQUIRE(writeMouseProfile(path, p, error));
  MouseProfile q;
  REQUIRE(readMouseProfile(path, q, error));
  CHECK(q.name == p.name);
  CHECK(q.vendorId == 0x0458);
  CHECK(q.productId == 0x0138);
  CHECK(q.surface == p.surface);
  CHECK(q.serial.empty());
  CHECK(q.cpi == 1200);
  CHECK(q.countMmX == Approx(p.countMmX).epsilon(1e-9));
  CHECK(q.countMmY == Approx(p.countMmY).epsilon(1e-9));
  DeviceSpec spec;
  REQUIRE(q.applyTo(spec));
  CHECK(spec.countMm == Approx(100.0 / 4731).epsilon(1e-9));
  CHECK(spec.countMmY == Approx(100.0 / 4690).epsilon(1e-9));
  CHECK(spec.updateRateHz == 500);
  CHECK(spec.swapXY == 0);  // a profile without axes: the mouse's own
  CHECK(spec.signX == 1);
  CHECK(spec.signY == 1);

  // Only the CPI: the count size comes from it.
  MouseProfile cpiOnly;
  cpiOnly.cpi = 800;
  REQUIRE(writeMouseProfile(path, cpiOnly, error));
  REQUIRE(readMouseProfile(path, q, error));
  DeviceSpec fromCpi;
  REQUIRE(q.applyTo(fromCpi));
  CHECK(fromCpi.countMm == Approx(25.4 / 800));
  CHECK(fromCpi.countMmY == 0);        // as x: the CPI is the same on both axes
  CHECK(fromCpi.updateRateHz == 125);  // untouched
  CHECK_FALSE(MouseProfile{}.applyTo(fromCpi));
}

TEST_CASE("mouse profile: malformed lines are named, unknown keys ignored", "[profile]") {
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/mouse-profile-bad.txt";
  std::string error;
  MouseProfile p;
  { std::ofstream(path) << "# kf-mouse-profile 1\nfutureKey = 3\ncountMmX = 0.02\n"; }
  REQUIRE(readMouseProfile(path, p, error));
  CHECK(p.countMmX == 0.02);
  for (const char* bad : {"countMmX = -0.02\n", "countMmX = 0.02mm\n", "cpi = nan\n", "just words\n",
                          "vendorId = 12345\n", "signX = 0\n", "signY = -2\n", "swapXY = yes\n", "swapXY = 2\n"}) {
    { std::ofstream(path) << "# kf-mouse-profile 1\n" << bad; }
    CHECK_FALSE(readMouseProfile(path, p, error));
    CHECK(error.find(":2:") != std::string::npos);
  }
  CHECK_FALSE(readMouseProfile(path + ".missing", p, error));
}

TEST_CASE("mouse profile: the axes' swap and signs are written, read back and applied", "[profile]") {
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/mouse-profile-axes.txt";
  MouseProfile p;
  p.countMmX = 0.02;
  p.countMmY = 0.03;
  p.swapXY = true;
  p.signX = 1;
  p.signY = -1;
  std::string error;
  REQUIRE(writeMouseProfile(path, p, error));
  MouseProfile q;
  REQUIRE(readMouseProfile(path, q, error));
  CHECK(q.swapXY);
  CHECK(q.signX == 1);
  CHECK(q.signY == -1);
  DeviceSpec spec;
  REQUIRE(q.applyTo(spec));
  REQUIRE(spec.isValid(&error));
  // The mouse in the puck turned a quarter: its +y is the surface's +x, its +x the surface's
  // -y. 100 counts along its x, 50 along its y.
  double xMm = 0.0, yMm = 0.0;
  spec.countsToMm(100, 50, xMm, yMm);
  CHECK(xMm == Approx(50 * 0.02));    // x from the mouse's y, at countMmX
  CHECK(yMm == Approx(-100 * 0.03));  // y from the mouse's x, reversed, at countMmY
}

TEST_CASE("counts to mm: countMmY sizes y, 0 means as x, signs reverse, a spec refuses sign 0", "[profile]") {
  DeviceSpec spec;
  spec.countMm = 0.02;
  double xMm = 0.0, yMm = 0.0;
  spec.countsToMm(10, -20, xMm, yMm);
  CHECK(xMm == Approx(0.2));
  CHECK(yMm == Approx(-0.4));  // countMmY 0: y counts as big as x's
  spec.countMmY = 0.05;
  spec.signX = -1;
  spec.countsToMm(10, -20, xMm, yMm);
  CHECK(xMm == Approx(-0.2));
  CHECK(yMm == Approx(-1.0));
  std::string error;
  CHECK(spec.isValid(&error));
  CHECK(spec.applyOverride("signY", -1, &error));
  CHECK_FALSE(spec.applyOverride("signY", 2, &error));
  CHECK_FALSE(spec.applyOverride("swapXY", 0.5, &error));
  spec.signY = 0;
  CHECK_FALSE(spec.isValid(&error));
  CHECK(error.find("signX and signY") != std::string::npos);
  spec.signY = 1;
  spec.countMmY = 1e-6;
  CHECK_FALSE(spec.isValid(&error));
}
