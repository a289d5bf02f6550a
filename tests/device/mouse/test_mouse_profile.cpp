// Counts per mm from a measured stroke, CPI as a starting value, and the profile file.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>

#include "mouse/MouseProfile.hpp"

using namespace kf;

TEST_CASE("count size from a measured stroke, either direction; CPI as a starting value", "[profile]") {
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
  CHECK(spec.updateRateHz == 500);

  // Only the CPI: the count size comes from it.
  MouseProfile cpiOnly;
  cpiOnly.cpi = 800;
  REQUIRE(writeMouseProfile(path, cpiOnly, error));
  REQUIRE(readMouseProfile(path, q, error));
  DeviceSpec fromCpi;
  REQUIRE(q.applyTo(fromCpi));
  CHECK(fromCpi.countMm == Approx(25.4 / 800));
  CHECK(fromCpi.updateRateHz == 125);  // untouched
  CHECK_FALSE(MouseProfile{}.applyTo(fromCpi));
}

TEST_CASE("mouse profile: malformed lines are named; unknown keys ignored", "[profile]") {
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/mouse-profile-bad.txt";
  std::string error;
  MouseProfile p;
  { std::ofstream(path) << "# kf-mouse-profile 1\nfutureKey = 3\ncountMmX = 0.02\n"; }
  REQUIRE(readMouseProfile(path, p, error));
  CHECK(p.countMmX == 0.02);
  for (const char* bad :
       {"countMmX = -0.02\n", "countMmX = 0.02mm\n", "cpi = nan\n", "just words\n", "vendorId = 12345\n"}) {
    { std::ofstream(path) << "# kf-mouse-profile 1\n" << bad; }
    CHECK_FALSE(readMouseProfile(path, p, error));
    CHECK(error.find(":2:") != std::string::npos);
  }
  CHECK_FALSE(readMouseProfile(path + ".missing", p, error));
}
