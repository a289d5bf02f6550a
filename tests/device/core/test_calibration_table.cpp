#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "core/force/CalibrationTable.hpp"

using namespace kf;

namespace {
CalibrationTable tableOf(std::vector<CalibrationPoint> points) {
  CalibrationTable table;
  std::string error;
  INFO(error);
  REQUIRE(CalibrationTable::fromPoints(std::move(points), table, error));
  return table;
}
}  // namespace

TEST_CASE("calibration is exact at the table points and linear between them", "[calibration]") {
  const CalibrationTable table = tableOf({{0.0, 0.14}, {0.25, 0.3}, {0.5, 0.7}, {1.0, 1.4}});
  for (const CalibrationPoint& p : table.points()) {
    CHECK(table.driveForForce(p.forceN) == p.drive);
    CHECK(table.forceForDrive(p.drive) == p.forceN);
  }
  CHECK(table.driveForForce(0.5) == Approx(0.375));
  CHECK(table.forceForDrive(0.75) == Approx(1.05));
  // Inverse of forward over the whole range.
  for (int i = 0; i <= 1000; ++i) {
    const double drive = i / 1000.0;
    CHECK(table.driveForForce(table.forceForDrive(drive)) == Approx(drive).margin(1e-12));
  }
}

TEST_CASE("calibration clamps outside the table and maps NaN to the lowest drive", "[calibration]") {
  const CalibrationTable table = tableOf({{0.1, 0.2}, {0.9, 1.2}});
  CHECK(table.driveForForce(0.0) == 0.1);
  CHECK(table.driveForForce(-5.0) == 0.1);
  CHECK(table.driveForForce(100.0) == 0.9);
  CHECK(table.driveForForce(std::numeric_limits<double>::infinity()) == 0.9);
  CHECK(table.driveForForce(-std::numeric_limits<double>::infinity()) == 0.1);
  CHECK(table.driveForForce(std::numeric_limits<double>::quiet_NaN()) == 0.1);
  CHECK(table.forceForDrive(0.0) == 0.2);
  CHECK(table.forceForDrive(1.0) == 1.2);
  CHECK(table.forceForDrive(std::numeric_limits<double>::quiet_NaN()) == 0.2);
}

TEST_CASE("flat segments give their lowest drive", "[calibration]") {
  // A coil that saturates at the top and a dead zone at the bottom.
  const CalibrationTable table =
      tableOf({{0.0, 0.14}, {0.1, 0.14}, {0.2, 0.14}, {0.5, 0.8}, {0.6, 0.8}, {0.8, 1.3}, {1.0, 1.3}});
  CHECK(table.driveForForce(0.14) == 0.0);
  CHECK(table.driveForForce(0.8) == 0.5);
  CHECK(table.driveForForce(1.3) == 0.8);
  CHECK(table.driveForForce(2.0) == 0.8);
  CHECK(table.driveForForce(0.15) > 0.2);  // just above the dead zone: past it
  CHECK(table.driveForForce(0.15) < 0.21);
  CHECK(table.driveForForce(0.8000001) > 0.6);
  // Monotone over a dense sweep.
  double previous = -1.0;
  for (int i = 0; i <= 20000; ++i) {
    const double drive = table.driveForForce(0.1 + i * 1.3 / 20000.0);
    CHECK(drive >= previous);
    previous = drive;
  }
}

TEST_CASE("a single point maps every force to its drive", "[calibration]") {
  const CalibrationTable table = tableOf({{0.4, 0.6}});
  for (double f : {0.0, 0.6, 1.0, 1e9}) CHECK(table.driveForForce(f) == 0.4);
  for (double d : {0.0, 0.4, 1.0}) CHECK(table.forceForDrive(d) == 0.6);
}

TEST_CASE("huge and tiny ranges stay finite and monotone", "[calibration]") {
  const CalibrationTable huge = tableOf({{0.0, 0.0}, {1e-9, 1e-300}, {0.5, 1e300}, {1.0, 1.7e308}});
  CHECK(huge.driveForForce(1e-300) == 1e-9);
  CHECK(huge.driveForForce(1.7e308) == 1.0);
  CHECK(std::isfinite(huge.driveForForce(1e308)));
  CHECK(huge.driveForForce(1e308) > 0.5);
  CHECK(huge.driveForForce(5e-301) == Approx(0.5e-9));
  const double denormal = std::numeric_limits<double>::denorm_min();
  const CalibrationTable tiny = tableOf({{0.0, 0.0}, {1.0, 100 * denormal}});
  CHECK(tiny.driveForForce(50 * denormal) == Approx(0.5));
  CHECK(tiny.forceForDrive(0.5) == 50 * denormal);
}

TEST_CASE("tables that are not monotone or malformed are rejected with a clear error", "[calibration]") {
  CalibrationTable table;
  std::string error;
  CHECK_FALSE(CalibrationTable::fromPoints({}, table, error));
  CHECK_FALSE(CalibrationTable::fromPoints({{0.0, 0.5}, {0.5, 0.4}}, table, error));
  CHECK(error.find("not monotone") != std::string::npos);
  CHECK_FALSE(CalibrationTable::fromPoints({{0.5, 0.5}, {0.5, 0.6}}, table, error));
  CHECK(error.find("ascend") != std::string::npos);
  CHECK_FALSE(CalibrationTable::fromPoints({{0.0, 0.5}, {1.5, 0.6}}, table, error));
  CHECK_FALSE(CalibrationTable::fromPoints({{0.0, std::nan("")}}, table, error));
  CHECK_FALSE(CalibrationTable::fromPoints({{0.0, -0.1}}, table, error));

  CHECK_FALSE(CalibrationTable::parse("", table, error));
  CHECK_FALSE(CalibrationTable::parse("0 0.14\n1 1.4\n", table, error));
  CHECK(error.find("header") != std::string::npos);
  CHECK_FALSE(CalibrationTable::parse("kf-calibration 2\n0 0.1\n", table, error));
  CHECK(error == "line 1: calibration format version 2 is not 1");
  CHECK_FALSE(CalibrationTable::parse("# a comment only\n\n", table, error));
  CHECK(error == "empty file: expected the header \"kf-calibration 1\"");
  // Blank and comment lines count: the error names the file's own line.
  CHECK_FALSE(CalibrationTable::parse("# made by hand\nkf-calibration 1\n\n0 0.1 # low\n0.5\n", table, error));
  CHECK(error == "line 5: expected two numbers, drive (0..1) and force (N): \"0.5\"");
  CHECK_FALSE(CalibrationTable::parse("kf-calibration 1\n0 0.1\n0.5\n", table, error));
  CHECK(error.find("line 3") != std::string::npos);
  CHECK_FALSE(CalibrationTable::parse("kf-calibration 1\n0 0.1 7\n", table, error));
  CHECK_FALSE(CalibrationTable::parse("kf-calibration 1\n0x 0.1\n", table, error));
  CHECK_FALSE(CalibrationTable::parse("kf-calibration 1\n0 0.5\n1 0.3\n", table, error));
  CHECK(error.find("not monotone") != std::string::npos);
  CHECK_FALSE(CalibrationTable::parse("kf-calibration 1\n# nothing\n", table, error));
  CHECK_FALSE(CalibrationTable::load("/nonexistent/kf.cal", table, error));
  CHECK(error.find("cannot open") != std::string::npos);
}

TEST_CASE("a table saved to a file loads back the same, with its serial", "[calibration]") {
  CalibrationTable table = tableOf({{0.0, 0.14}, {0.3, 0.33333333333333331}, {1.0, 1.4}});
  table.setSerial("KF0042");
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/calibration-roundtrip.txt";
  std::string error;
  REQUIRE(table.save(path, error));
  CalibrationTable loaded;
  REQUIRE(CalibrationTable::load(path, loaded, error));
  CHECK(loaded.serial() == "KF0042");
  REQUIRE(loaded.points().size() == 3);
  for (size_t i = 0; i < 3; ++i) {
    CHECK(loaded.points()[i].drive == table.points()[i].drive);
    CHECK(loaded.points()[i].forceN == table.points()[i].forceN);
  }
  CalibrationTable parsed;
  REQUIRE(CalibrationTable::parse("kf-calibration 1  # comment\n\n  0 0.14\n 1 1.4 # top\n", parsed, error));
  CHECK(parsed.points().size() == 2);
}

TEST_CASE("a table drives only the board it names", "[calibration]") {
  CalibrationTable table = tableOf({{0.0, 0.14}, {1.0, 1.4}});
  std::string error;
  CHECK_FALSE(table.checkBoard(true, "KF0042", error));  // names no board: cannot be checked
  CHECK(error.find("names no board") != std::string::npos);
  CHECK(error.find("add \"serial KF0042\"") != std::string::npos);  // the line to add
  table.setSerial("KF0042");
  CHECK(table.checkBoard(true, "KF0042", error));
  CHECK_FALSE(table.checkBoard(true, "KF0043", error));
  CHECK(error.find("measured on board KF0042, not on this one (KF0043)") != std::string::npos);
  CHECK_FALSE(table.checkBoard(false, "", error));
  CHECK(error.find("no board is open") != std::string::npos);
  CHECK(error.size() < 150);
  // A board open that reports no serial: no table matches it, whatever the table names.
  CHECK_FALSE(table.checkBoard(true, "", error));
  CHECK(error.find("reports no USB serial") != std::string::npos);
  CHECK(error.find("no board is open") == std::string::npos);
  CHECK(error.size() < 150);
  table.setSerial("");
  CHECK_FALSE(table.checkBoard(true, "", error));
  CHECK(error.find("reports no USB serial") !=
        std::string::npos);  // a /kfFail reason holds 200 characters with the command and path
  // The serial line of a file: one word, required when present.
  CalibrationTable parsed;
  CHECK_FALSE(CalibrationTable::parse("kf-calibration 1\nserial\n0 0.14\n", parsed, error));
  CHECK(error.find("line 2") != std::string::npos);
  CHECK_FALSE(CalibrationTable::parse("kf-calibration 1\nserial A B\n0 0.14\n", parsed, error));
  REQUIRE(CalibrationTable::parse("kf-calibration 1\nserial KF-0001 # the board\n0 0.14\n", parsed, error));
  CHECK(parsed.serial() == "KF-0001");
}
