// HidRecorderFile: reads the text recordings of hid-recorder (hid-tools project): the report
// descriptor (R:), name (N:), physical path (P:), ids (I:) and timed raw reports (E:).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace kf {

struct HidRecordedEvent {
  double timeS = 0.0;
  std::vector<uint8_t> bytes;  // as received, report ID first when the device numbers reports
};

struct HidRecording {
  std::vector<uint8_t> descriptor;
  std::string name;
  std::string physicalPath;
  uint32_t bus = 0, vendorId = 0, productId = 0;
  std::vector<HidRecordedEvent> events;
  std::string warning;  // e.g. a last line cut mid-way (dropped); empty if none
};

// hid-recorder writes a 4096-byte report as 3 characters a byte; anything longer is not one.
constexpr size_t kMaxHidRecorderLineChars = 16384;

// True if the first record of the file looks like hid-recorder output (R: or D: line); false
// for anything that is not a regular file (it is never read).
bool isHidRecorderFile(const std::string& path);
// Reads the first device of the file (D: 0 or no D: lines). False with a message naming the
// line on malformed records (lengths that do not match, bad hex, no descriptor, non-finite
// times, lines over kMaxHidRecorderLineChars). A last line without its newline (a recording
// cut short) is dropped with out.warning.
bool readHidRecorderFile(const std::string& path, HidRecording& out, std::string& error);

}  // namespace kf
