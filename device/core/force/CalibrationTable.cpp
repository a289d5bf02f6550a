#include "core/force/CalibrationTable.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/force/TableLines.hpp"

namespace kf {

namespace {
constexpr const char* kHeader = "kf-calibration";
constexpr int kVersion = 1;
}  // namespace

CalibrationTable CalibrationTable::linear(double minForceN, double maxForceN) {
  CalibrationTable table;
  table.points_ = {{0.0, minForceN}, {1.0, std::max(minForceN, maxForceN)}};
  return table;
}

bool CalibrationTable::fromPoints(std::vector<CalibrationPoint> points, CalibrationTable& out, std::string& error) {
  if (points.empty()) {
    error = "a calibration table needs at least one point";
    return false;
  }
  char message[200];
  for (size_t i = 0; i < points.size(); ++i) {
    const CalibrationPoint& p = points[i];
    if (!std::isfinite(p.drive) || p.drive < 0.0 || p.drive > 1.0) {
      std::snprintf(message, sizeof message, "point %zu: drive %g is not in 0..1", i + 1, p.drive);
      error = message;
      return false;
    }
    if (!std::isfinite(p.forceN) || p.forceN < 0.0) {
      std::snprintf(message, sizeof message, "point %zu: force %g N is not a finite force >= 0", i + 1, p.forceN);
      error = message;
      return false;
    }
    if (i > 0 && !(p.drive > points[i - 1].drive)) {
      std::snprintf(message, sizeof message, "point %zu: drive %g does not ascend (previous %g)", i + 1, p.drive,
                    points[i - 1].drive);
      error = message;
      return false;
    }
    if (i > 0 && p.forceN < points[i - 1].forceN) {
      std::snprintf(message, sizeof message, "not monotone: point %zu has %g N at drive %g, less than %g N at drive %g",
                    i + 1, p.forceN, p.drive, points[i - 1].forceN, points[i - 1].drive);
      error = message;
      return false;
    }
  }
  out.points_ = std::move(points);
  return true;
}

bool CalibrationTable::parse(const std::string& text, CalibrationTable& out, std::string& error) {
  TableLines lines(text, kHeader, kVersion, "calibration format");
  std::istringstream fields;
  std::string first, serial;
  std::vector<CalibrationPoint> points;
  auto fail = [&](const std::string& what) {
    error = lines.error(what);
    return false;
  };
  while (lines.next(fields, first)) {
    if (first == "serial") {
      std::string rest;
      if (!(fields >> serial) || (fields >> rest)) return fail("expected \"serial <the board's USB serial>\"");
      continue;
    }
    CalibrationPoint point;
    std::istringstream firstField(first);
    std::string rest;
    if (!(firstField >> point.drive) || !firstField.eof() || !(fields >> point.forceN) || (fields >> rest))
      return fail("expected two numbers, drive (0..1) and force (N): \"" + fields.str() + "\"");
    points.push_back(point);
  }
  if (!lines.failure().empty()) {
    error = lines.failure();
    return false;
  }
  CalibrationTable table;
  if (!fromPoints(std::move(points), table, error)) return false;
  table.serial_ = serial;
  out = std::move(table);
  return true;
}

bool CalibrationTable::checkBoard(bool boardOpen, const std::string& boardSerial, std::string& error) const {
  // Short enough for a /kfFail reason (200 characters) with the command's name.
  if (boardOpen && boardSerial.empty()) {
    error =
        "the board reports no USB serial, so no table can be matched to it: give its firmware one "
        "(PROTOCOL.md 1), or use it uncalibrated";
    return false;
  }
  if (serial_.empty()) {
    error = "the table names no board: if it was measured on this one, add \"serial " +
            (boardSerial.empty() ? std::string("<serial>") : boardSerial) +
            "\" after its header; else measure this board";
    return false;
  }
  if (!boardOpen) {
    error = "the table is for board " + serial_ + " and no board is open: add the board first, then load its table";
    return false;
  }
  if (boardSerial != serial_) {
    error = "the table was measured on board " + serial_ + ", not on this one (" + boardSerial +
            "): measure this board and load its own table";
    return false;
  }
  return true;
}

bool CalibrationTable::load(const std::string& path, CalibrationTable& out, std::string& error) {
  std::ifstream file(path);
  if (!file) {
    error = path + ": cannot open";
    return false;
  }
  std::stringstream text;
  text << file.rdbuf();
  if (!parse(text.str(), out, error)) {
    error = path + ": " + error;
    return false;
  }
  return true;
}

std::string CalibrationTable::toText() const {
  std::ostringstream text;
  text.precision(17);
  text << kHeader << ' ' << kVersion << "\n";
  if (!serial_.empty()) text << "serial " << serial_ << "\n";
  text << "# drive (0..1 of full-scale current)  force (N)\n";
  for (const CalibrationPoint& p : points_) text << p.drive << ' ' << p.forceN << "\n";
  return text.str();
}

bool CalibrationTable::save(const std::string& path, std::string& error) const {
  std::ofstream file(path);
  if (!(file << toText()) || !file.flush()) {
    error = path + ": cannot write";
    return false;
  }
  return true;
}

double CalibrationTable::driveForForce(double forceN) const {
  const CalibrationPoint& first = points_.front();
  if (!(forceN > first.forceN)) return first.drive;  // also NaN
  if (forceN >= points_.back().forceN) {
    // The least drive reaching the top force (a flat top segment is not climbed).
    for (const CalibrationPoint& p : points_)
      if (p.forceN >= points_.back().forceN) return p.drive;
  }
  // The first point with force >= forceN; forceN lies in (previous force, its force].
  const auto upper = std::lower_bound(points_.begin(), points_.end(), forceN,
                                      [](const CalibrationPoint& p, double f) { return p.forceN < f; });
  const CalibrationPoint& hi = *upper;
  if (hi.forceN == forceN) return hi.drive;  // exact at table points, lowest of a flat run
  const CalibrationPoint& lo = *(upper - 1);
  const double fraction = (forceN - lo.forceN) / (hi.forceN - lo.forceN);  // hi.forceN > lo.forceN here
  return std::clamp(lo.drive + fraction * (hi.drive - lo.drive), lo.drive, hi.drive);
}

double CalibrationTable::forceForDrive(double drive) const {
  if (!(drive > points_.front().drive)) return points_.front().forceN;
  if (drive >= points_.back().drive) return points_.back().forceN;
  const auto upper = std::lower_bound(points_.begin(), points_.end(), drive,
                                      [](const CalibrationPoint& p, double d) { return p.drive < d; });
  const CalibrationPoint& hi = *upper;
  if (hi.drive == drive) return hi.forceN;
  const CalibrationPoint& lo = *(upper - 1);
  const double fraction = (drive - lo.drive) / (hi.drive - lo.drive);
  return std::clamp(lo.forceN + fraction * (hi.forceN - lo.forceN), lo.forceN, hi.forceN);
}

}  // namespace kf
