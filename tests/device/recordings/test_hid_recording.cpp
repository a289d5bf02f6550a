#include <catch2/catch.hpp>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "DeviceFactory.hpp"
#include "hid/HidMouseDecoder.hpp"
#include "hid/HidReportDescriptor.hpp"
#include "recordings/HidRecorderFile.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;

namespace {
// Independent of the parser: the Genius mouse's report 1 is ID, buttons byte, X and Y as
// little-endian int16 at bytes 2-3 and 4-5.
void sumByHand(long long& sumX, long long& sumY, int& lines) {
  std::ifstream in(KF_HID_RECORDING);
  std::string line;
  sumX = sumY = 0;
  lines = 0;
  while (std::getline(in, line)) {
    if (line.rfind("E:", 0) != 0) continue;
    std::istringstream fields(line.substr(2));
    std::string timeS, size, hex;
    fields >> timeS >> size;
    unsigned bytes[8] = {};
    for (unsigned& byte : bytes) {
      fields >> hex;
      byte = static_cast<unsigned>(std::strtoul(hex.c_str(), nullptr, 16));
    }
    sumX += static_cast<int16_t>(bytes[2] | bytes[3] << 8);
    sumY += static_cast<int16_t>(bytes[4] | bytes[5] << 8);
    ++lines;
  }
}

HidMouseDelta decodeHex(const HidMouseDecoder& decoder, std::vector<uint8_t> bytes) {
  HidMouseDelta delta;
  REQUIRE(decoder.decode(bytes.data(), bytes.size(), delta));
  return delta;
}
}  // namespace

TEST_CASE("hid-recorder file of a real mouse: header and descriptor", "[hid]") {
  HidRecording recording;
  std::string error;
  REQUIRE(readHidRecorderFile(KF_HID_RECORDING, recording, error));
  CHECK(recording.descriptor.size() == 181);
  CHECK(recording.name == "Genius Gila Gaming Mouse");
  CHECK(recording.vendorId == 0x0458);
  CHECK(recording.productId == 0x0138);
  CHECK(recording.events.size() == 738);
  CHECK(recording.events[1].timeS == Approx(0.025885));

  HidReportDescriptor descriptor;
  REQUIRE(parseHidReportDescriptor(recording.descriptor.data(), recording.descriptor.size(), descriptor, error));
  CHECK(descriptor.usesReportIds);
  CHECK(descriptor.inputReportBytes(1) == 8);
  HidMouseDecoder decoder;
  REQUIRE(decoder.build(descriptor, error));
  CHECK(decoder.mouseReportIds() == std::vector<uint8_t>{1});
}

TEST_CASE("hid-recorder reports decode to hand-decoded counts", "[hid]") {
  HidRecording recording;
  std::string error;
  REQUIRE(readHidRecorderFile(KF_HID_RECORDING, recording, error));
  HidReportDescriptor descriptor;
  REQUIRE(parseHidReportDescriptor(recording.descriptor.data(), recording.descriptor.size(), descriptor, error));
  HidMouseDecoder decoder;
  REQUIRE(decoder.build(descriptor, error));

  // E: 0.000000 8 01 00 00 00 ff ff 00 00
  HidMouseDelta delta = decodeHex(decoder, recording.events[0].bytes);
  CHECK(delta.dxCounts == 0);
  CHECK(delta.dyCounts == -1);
  CHECK(delta.buttons == 0);
  // E: 0.477871 8 01 00 ff ff 00 00 00 00
  delta = decodeHex(decoder, {0x01, 0x00, 0xff, 0xff, 0x00, 0x00, 0x00, 0x00});
  CHECK(delta.dxCounts == -1);
  CHECK(delta.dyCounts == 0);
  // E: 3.971834 8 01 08 01 00 ff ff 00 00: button 4 held
  delta = decodeHex(decoder, {0x01, 0x08, 0x01, 0x00, 0xff, 0xff, 0x00, 0x00});
  CHECK(delta.buttons == 0x8);
  CHECK(delta.dxCounts == 1);
  CHECK(delta.dyCounts == -1);
  // E: 6.835772 8 01 00 f9 ff fd ff 00 00
  delta = decodeHex(decoder, {0x01, 0x00, 0xf9, 0xff, 0xfd, 0xff, 0x00, 0x00});
  CHECK(delta.dxCounts == -7);
  CHECK(delta.dyCounts == -3);
  // Wheel and AC pan bytes do not leak into X/Y: E: 1.165862 8 01 00 00 00 00 00 00 ff
  delta = decodeHex(decoder, {0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xff});
  CHECK(delta.dxCounts == 0);
  CHECK(delta.dyCounts == 0);
  // Large 16-bit values (beyond int8).
  delta = decodeHex(decoder, {0x01, 0x1f, 0x34, 0x12, 0x01, 0x80, 0x00, 0x00});
  CHECK(delta.buttons == 0x1f);
  CHECK(delta.dxCounts == 0x1234);
  CHECK(delta.dyCounts == -32767);
}

TEST_CASE("replaying a hid-recorder file sums the same counts as the raw bytes", "[hid]") {
  long long byHandX = 0, byHandY = 0;
  int lines = 0;
  sumByHand(byHandX, byHandY, lines);
  REQUIRE(lines == 738);

  DeviceSpec spec;
  std::vector<TimedReport> reports;
  std::string error;
  size_t skipped = 0;
  REQUIRE(loadReplayReports(KF_HID_RECORDING, spec, reports, error, &skipped));
  CHECK(skipped == 0);
  REQUIRE(reports.size() == 738);
  long long sumX = 0, sumY = 0;
  for (const TimedReport& timed : reports) {
    sumX += timed.report.dxCounts;
    sumY += timed.report.dyCounts;
  }
  CHECK(sumX == byHandX);
  CHECK(sumY == byHandY);
  CHECK(sumX == -67);
  CHECK(sumY == -40);

  // Through a lockstep replay device: reports arrive at their recorded times.
  auto device = openReplayDevice(KF_HID_RECORDING, spec, true, error);
  REQUIRE(device);
  MouseReport buffer[64];
  device->pump(0.2);
  const int early = device->popReports(buffer, 64);
  CHECK(early == 6);  // the events up to 0.171879 s
  CHECK(buffer[5].deviceTimeS == Approx(0.171879));
  long long deviceSumX = 0;
  for (int i = 0; i < early; ++i) deviceSumX += buffer[i].dxCounts;
  for (double timeS = 0.3; timeS < 60.0; timeS += 0.1) {
    device->pump(timeS);
    int n = 0;
    while ((n = device->popReports(buffer, 64)) > 0)
      for (int i = 0; i < n; ++i) deviceSumX += buffer[i].dxCounts;
  }
  CHECK(deviceSumX == byHandX);
  CHECK(device->telemetry().reports == 738);
}

TEST_CASE("malformed hid-recorder files give line-numbered errors", "[hid]") {
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/bad.hid";
  HidRecording recording;
  std::string error;
  std::ofstream(path) << "R: 3 05 01\n";
  CHECK_FALSE(readHidRecorderFile(path, recording, error));
  CHECK(error.find(":1:") != std::string::npos);
  std::ofstream(path) << "# comment\nR: 2 05 01\nE: 0.1 3 01 02\n";
  CHECK_FALSE(readHidRecorderFile(path, recording, error));
  CHECK(error.find(":3:") != std::string::npos);
  std::ofstream(path) << "N: no descriptor\n";
  CHECK_FALSE(readHidRecorderFile(path, recording, error));
  // A file with a descriptor that has no mouse cannot be replayed.
  std::ofstream(path) << "R: 2 05 01\nE: 0.1 1 01\n";
  CHECK_FALSE(openReplayDevice(path, DeviceSpec{}, true, error));
  CHECK_FALSE(error.empty());
}
