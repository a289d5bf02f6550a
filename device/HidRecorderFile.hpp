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
};

// True if the first record of the file looks like hid-recorder output (R: or D: line).
bool isHidRecorderFile(const std::string& path);
// Reads the first device of the file (D: 0 or no D: lines). False with a message naming the
// line on malformed records (lengths that do not match, bad hex, no descriptor).
bool readHidRecorderFile(const std::string& path, HidRecording& out, std::string& error);

}  // namespace kf
