// A recording's file is the same on every system (core/files/FileDescriptors*.cpp): its lines
// end in a bare \n (Windows opens it in binary mode), and one file recorded twice is refused
// while another file is not (Windows identifies a file by its volume and index: its st_ino is 0).
// Runs in every build, the Windows one under Wine included (scripts/check.sh cross).
#include <algorithm>
#include <catch2/catch.hpp>
#include <fstream>
#include <iterator>
#include <string>

#include "core/files/SessionFile.hpp"
#include "core/spec/DeviceSpec.hpp"

using namespace kf;

TEST_CASE("a recording's lines end in a bare newline, and only the same file is refused twice", "[record]") {
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/recording-bytes.kfs";
  const std::string other = std::string(KF_TEST_OUTPUT_DIR) + "/recording-bytes-other.kfs";
  std::string error;
  Recorder recorder;
  REQUIRE(recorder.open(path, DeviceSpec{}, error));
  MouseReport report;
  report.dxCounts = 3;
  recorder.writeReport(0.001, report);
  recorder.writeOff(0.002, OffCause::kClose);
  REQUIRE(recorder.flush());

  Recorder second;
  CHECK_FALSE(second.open(path, DeviceSpec{}, error));
  CHECK(error.find("another device is recording to this file") != std::string::npos);
  error.clear();
  CHECK(second.open(other, DeviceSpec{}, error));
  CHECK(error.empty());
  second.close();
  recorder.close();

  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(bytes.find('\r') == std::string::npos);
  CHECK(std::count(bytes.begin(), bytes.end(), '\n') >= 3);  // the header, the report, the off record
  CHECK(bytes.back() == '\n');
}
