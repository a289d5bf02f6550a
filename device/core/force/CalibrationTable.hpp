// CalibrationTable: a board's measured force (N) at drive levels (0..1 of full-scale coil
// current), and its inverse, force -> drive, that the force path uses. Monotone: drives
// strictly ascend, forces never descend (flat segments allowed). Exact at the table points,
// linear in between, clamped outside. The file format ("kf-calibration 1") is in
// docs/calibration-format.md.
#pragma once

#include <string>
#include <vector>

namespace kf {

struct CalibrationPoint {
  double drive = 0.0;  // 0..1
  double forceN = 0.0;
};

class CalibrationTable {
 public:
  // The identity of an uncalibrated board: drive 0 -> minForceN, drive 1 -> maxForceN.
  static CalibrationTable linear(double minForceN, double maxForceN);

  // False, with a message naming the first bad point, unless the points form a usable table.
  static bool fromPoints(std::vector<CalibrationPoint> points, CalibrationTable& out, std::string& error);
  // Parses the text of a calibration file; errors name the line.
  static bool parse(const std::string& text, CalibrationTable& out, std::string& error);
  static bool load(const std::string& path, CalibrationTable& out, std::string& error);
  bool save(const std::string& path, std::string& error) const;
  std::string toText() const;

  // The least drive that gives forceN (flat segment: its lowest drive). Below the first
  // point's force: its drive; above the last: the last drive. NaN: the first drive.
  double driveForForce(double forceN) const;
  // The force at a drive level, linear between points, clamped to the table's ends.
  double forceForDrive(double drive) const;

  double minForceN() const { return points_.front().forceN; }
  double maxForceN() const { return points_.back().forceN; }
  const std::vector<CalibrationPoint>& points() const { return points_; }
  const std::string& serial() const { return serial_; }
  void setSerial(std::string serial) { serial_ = std::move(serial); }

  // May this table drive the open board (boardOpen) whose USB serial is boardSerial? Only when
  // it names that board: a table measured on another board is refused, and so is one that
  // names none (it cannot be checked; docs/calibration-format.md says why), and any table for a
  // board that reports no serial (it cannot be matched). False with a message that says what
  // to do.
  bool checkBoard(bool boardOpen, const std::string& boardSerial, std::string& error) const;

 private:
  std::vector<CalibrationPoint> points_{{0.0, 0.0}, {1.0, 0.0}};
  std::string serial_;  // of the board it was measured on; empty: not named
};

}  // namespace kf
