// DriveCircuit: what lies between a sample value on a DC-coupled audio output and the coil's
// current (FrictionDrive, docs/drive-format.md): the interface channel's full-scale volts and
// sign, the voltage-controlled current source's transconductance and latency, the magnet's force
// lag, the current the circuit is declared safe for, and the magnet's table (a
// kf-calibration file: force at fractions of fullScaleCurrentA). Read from a "kf-drive 1" file,
// checked as a whole: a file whose numbers disagree is refused with the reason.
#pragma once

#include <string>

#include "core/force/CalibrationTable.hpp"

namespace kf {

struct DriveCircuit {
  double fullScaleCurrentA = 0.0;      // the coil current at the magnet table's drive 1
  double transconductanceAPerV = 0.0;  // the current source: coil amps per input volt
  double outputFullScaleV = 0.0;       // the interface channel: volts at sample value 1
  double outputSign = 1.0;             // -1: the channel (or the source) inverts
  double maxSafeCurrentA = 0.0;        // the circuit's declared limit: the drive never exceeds it
  double currentSourceLatencyS = 0.0;  // a delay: input volts to coil current (the loop's, measured)
  double magnetLagS = 0.0;             // a delay: force onset behind the coil current (force gauge)
  CalibrationTable magnet;             // force (N) at fractions of fullScaleCurrentA

  // The highest drive level (fraction of fullScaleCurrentA) the circuit may be given.
  double safeDriveLevel() const;
  // The sample value for a drive level (0..1 of fullScaleCurrentA): signed, |value| <= 1.
  double sampleForDrive(double driveLevel) const;
  // What the drive adds to the force path beside the audio path, both through the interface:
  // the current source's delay and the magnet's (the server's block is the caller's,
  // FrictionDrive's). The coil's L/R is no delay here: a current source forces the current, and
  // L/R only slows the rise the supply limits (docs/current-source.md, section 4).
  double circuitLatencyS() const { return currentSourceLatencyS + magnetLagS; }

  // Parses a kf-drive file's text; `magnetTablePath` receives the table's path as written
  // (relative to the file's folder unless absolute). Errors name the line. Checks every field
  // alone, not the whole (check()).
  static bool parse(const std::string& text, DriveCircuit& out, std::string& magnetTablePath, std::string& error);
  // Reads the file and the magnet table it names, then check(). False with "path: reason".
  static bool load(const std::string& path, DriveCircuit& out, std::string& error);
  // The fields together: the safe current within what the interface can make the source give,
  // and so on. False with what disagrees.
  bool check(std::string& error) const;
};

}  // namespace kf
