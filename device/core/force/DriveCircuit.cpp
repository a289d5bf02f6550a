#include "core/force/DriveCircuit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/files/TextFileReader.hpp"
#include "core/force/TableLines.hpp"

namespace kf {

namespace {

constexpr const char* kDriveHeader = "kf-drive";
constexpr int kDriveVersion = 1;
constexpr uint64_t kMaxFileBytes = 64 * 1024;  // a dozen lines; anything larger is not one
constexpr size_t kMaxLineChars = 1024;

// One numeric field: its name, where it goes, the range it may hold and what it is.
struct Field {
  const char* key;
  double DriveCircuit::*member;
  double lo;
  double hi;
  bool loOpen;  // lo itself is not allowed (a zero current or gain)
};

constexpr Field kFields[] = {
    {"fullScaleCurrentA", &DriveCircuit::fullScaleCurrentA, 0.0, 100.0, true},
    {"transconductanceAPerV", &DriveCircuit::transconductanceAPerV, 0.0, 100.0, true},
    {"outputFullScaleV", &DriveCircuit::outputFullScaleV, 0.0, 100.0, true},
    {"outputSign", &DriveCircuit::outputSign, -1.0, 1.0, false},
    {"maxSafeCurrentA", &DriveCircuit::maxSafeCurrentA, 0.0, 100.0, true},
    {"currentSourceLatencyS", &DriveCircuit::currentSourceLatencyS, 0.0, 0.1, false},
    {"magnetLagS", &DriveCircuit::magnetLagS, 0.0, 0.1, false},
};
constexpr int kNumFields = sizeof kFields / sizeof kFields[0];

std::string folderOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

}  // namespace

double DriveCircuit::safeDriveLevel() const { return std::clamp(maxSafeCurrentA / fullScaleCurrentA, 0.0, 1.0); }

double DriveCircuit::sampleForDrive(double driveLevel) const {
  const double volts = driveLevel * fullScaleCurrentA / transconductanceAPerV;
  // check() keeps the safe range within full scale; the clamp keeps a rounding there too.
  return outputSign * std::clamp(volts / outputFullScaleV, 0.0, 1.0);
}

bool DriveCircuit::parse(const std::string& text, DriveCircuit& out, std::string& magnetTablePath, std::string& error) {
  TableLines lines(text, kDriveHeader, kDriveVersion, "drive format");
  std::istringstream fields;
  std::string key;
  bool seen[kNumFields] = {};
  DriveCircuit circuit;
  magnetTablePath.clear();
  auto fail = [&](const std::string& what) {
    error = lines.error(what);
    return false;
  };
  while (lines.next(fields, key)) {
    std::string rest;
    if (key == "magnetTable") {
      if (!magnetTablePath.empty()) return fail("magnetTable is given twice");
      if (!(fields >> magnetTablePath) || (fields >> rest))
        return fail("expected \"magnetTable <kf-calibration file>\"");
      continue;
    }
    const Field* field =
        std::find_if(std::begin(kFields), std::end(kFields), [&](const Field& f) { return key == f.key; });
    if (key == "coilTimeConstantS")  // an early field: L/R is no delay with a current source
      return fail(
          "coilTimeConstantS is no longer a field: declare magnetLagS, the force's delay behind the current "
          "measured with a force gauge (docs/drive-format.md)");
    if (field == std::end(kFields)) return fail("unknown field \"" + key + "\"");
    const int index = static_cast<int>(field - kFields);
    if (seen[index]) return fail(key + " is given twice");
    double value = 0.0;
    // Non-finite values too: libstdc++ does not read "nan" as a number and libc++ does.
    if (!(fields >> value) || (fields >> rest) || !std::isfinite(value))
      return fail("expected \"" + key + " <number>\"");
    const bool inRange =
        std::isfinite(value) && value <= field->hi && (field->loOpen ? value > field->lo : value >= field->lo);
    const bool isSign = field->member != &DriveCircuit::outputSign || value == 1.0 || value == -1.0;
    if (!inRange || !isSign) {
      char message[200];
      if (field->member == &DriveCircuit::outputSign)
        std::snprintf(message, sizeof message, "outputSign %g is not 1 or -1", value);
      else
        std::snprintf(message, sizeof message, "%s %g is not in %s%g, %g]", key.c_str(), value,
                      field->loOpen ? "(" : "[", field->lo, field->hi);
      return fail(message);
    }
    circuit.*(field->member) = value;
    seen[index] = true;
  }
  if (!lines.failure().empty()) {
    error = lines.failure();
    return false;
  }
  for (int i = 0; i < kNumFields; ++i)
    if (!seen[i]) {
      error = std::string("the field ") + kFields[i].key + " is missing (docs/drive-format.md)";
      return false;
    }
  if (magnetTablePath.empty()) {
    error = "the field magnetTable is missing: the magnet's kf-calibration file (docs/drive-format.md)";
    return false;
  }
  out = circuit;
  return true;
}

bool DriveCircuit::check(std::string& error) const {
  char message[300];
  // The most current the interface can make the source give, against what the drive asks for
  // at the top of its range: less, and the output would clip while the force path believes the
  // table (forces would be silently short).
  const double topA = std::min(fullScaleCurrentA, maxSafeCurrentA);
  const double reachA = outputFullScaleV * transconductanceAPerV;
  if (reachA < topA * (1.0 - 1e-9)) {
    std::snprintf(message, sizeof message,
                  "the interface's %g V full scale through %g A/V gives at most %g A, less than the %g A the drive "
                  "uses (min of fullScaleCurrentA and maxSafeCurrentA)",
                  outputFullScaleV, transconductanceAPerV, reachA, topA);
    error = message;
    return false;
  }
  // The magnet off (the table's first point) must itself be within the safe current.
  const double offA = magnet.points().front().drive * fullScaleCurrentA;
  if (offA > maxSafeCurrentA) {
    std::snprintf(message, sizeof message,
                  "maxSafeCurrentA %g A is below the magnet table's first point (%g A, its least force): the magnet "
                  "could not even be driven off",
                  maxSafeCurrentA, offA);
    error = message;
    return false;
  }
  return true;
}

bool DriveCircuit::load(const std::string& path, DriveCircuit& out, std::string& error) {
  TextFileReader reader;
  if (!reader.open(path, error, kMaxFileBytes)) return false;
  std::string text;
  std::string line;
  for (;;) {
    const TextFileReader::Line outcome = reader.next(line, kMaxLineChars);
    if (outcome == TextFileReader::Line::kEnd) break;
    if (outcome == TextFileReader::Line::kTooLong || outcome == TextFileReader::Line::kError) {
      error = path + ": line " + std::to_string(reader.lineNumber()) + " cannot be read or is too long";
      return false;
    }
    text += line;
    text += '\n';
    if (outcome == TextFileReader::Line::kCut) break;
  }
  DriveCircuit circuit;
  std::string tablePath;
  if (!parse(text, circuit, tablePath, error)) {
    error = path + ": " + error;
    return false;
  }
  if (tablePath.front() != '/') tablePath = folderOf(path) + "/" + tablePath;
  if (!CalibrationTable::load(tablePath, circuit.magnet, error)) {
    error = path + ": its magnetTable " + error;
    return false;
  }
  if (!circuit.check(error)) {
    error = path + ": " + error;
    return false;
  }
  out = std::move(circuit);
  return true;
}

}  // namespace kf
