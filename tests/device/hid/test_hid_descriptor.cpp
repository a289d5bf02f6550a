#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "hid/HidMouseDecoder.hpp"
#include "hid/HidReportDescriptor.hpp"
#include "sim/DeterministicRandom.hpp"

using namespace kf;

namespace {
using Bytes = std::vector<uint8_t>;

HidMouseDecoder decoderFor(const Bytes& descriptorBytes) {
  HidReportDescriptor descriptor;
  std::string error;
  REQUIRE(parseHidReportDescriptor(descriptorBytes.data(), descriptorBytes.size(), descriptor, error));
  HidMouseDecoder decoder;
  REQUIRE(decoder.build(descriptor, error));
  return decoder;
}

bool parses(const Bytes& bytes, std::string& error) {
  HidReportDescriptor descriptor;
  return parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error);
}

// The boot-protocol mouse: no report ID, 3 buttons, 5 bits padding, 8-bit X and Y.
const Bytes kBootMouse = {0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x09, 0x01, 0xa1, 0x00, 0x05, 0x09, 0x19,
                          0x01, 0x29, 0x03, 0x15, 0x00, 0x25, 0x01, 0x95, 0x03, 0x75, 0x01, 0x81, 0x02,
                          0x95, 0x01, 0x75, 0x05, 0x81, 0x01, 0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x15,
                          0x81, 0x25, 0x7f, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0xc0, 0xc0};

// Report ID 2, 8 buttons, X and Y as two packed 12-bit fields (3 bytes), an 8-bit wheel.
// A vendor feature collection before it, with Push/Pop around its own sizes.
const Bytes kPacked12 = {0x06, 0x00, 0xff, 0x09, 0x01, 0xa1, 0x01, 0x85, 0x05, 0xa4,  // vendor app, ID 5, Push
                         0x75, 0x08, 0x95, 0x04, 0x15, 0x00, 0x26, 0xff, 0x00, 0x09, 0x02, 0xb1, 0x02,  // feature
                         0xb4, 0xc0,                                                                    // Pop, end
                         0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x85, 0x02, 0x09, 0x01, 0xa1, 0x00, 0x05, 0x09, 0x19,
                         0x01, 0x29, 0x08, 0x15, 0x00, 0x25, 0x01, 0x75, 0x01, 0x95, 0x08, 0x81, 0x02, 0x05, 0x01,
                         0x09, 0x30, 0x09, 0x31, 0x16, 0x01, 0xf8, 0x26, 0xff, 0x07, 0x75, 0x0c, 0x95, 0x02, 0x81,
                         0x06, 0x09, 0x38, 0x15, 0x81, 0x25, 0x7f, 0x75, 0x08, 0x95, 0x01, 0x81, 0x06, 0xc0, 0xc0};
}  // namespace

TEST_CASE("8-bit boot mouse without report IDs", "[hid]") {
  const HidMouseDecoder decoder = decoderFor(kBootMouse);
  CHECK_FALSE(decoder.usesReportIds());
  HidMouseDelta delta;
  const Bytes report = {0x03, 0x02, 0xfe};
  REQUIRE(decoder.decode(report.data(), report.size(), delta));
  CHECK(delta.buttons == 3);
  CHECK(delta.dxCounts == 2);
  CHECK(delta.dyCounts == -2);
  const Bytes extremes = {0x04, 0x81, 0x7f};
  REQUIRE(decoder.decode(extremes.data(), extremes.size(), delta));
  CHECK(delta.buttons == 4);
  CHECK(delta.dxCounts == -127);
  CHECK(delta.dyCounts == 127);
  const Bytes tooShort = {0x00, 0x01};
  CHECK_FALSE(decoder.decode(tooShort.data(), tooShort.size(), delta));
}

TEST_CASE("12-bit fields packed two in three bytes, with report IDs and Push/Pop", "[hid]") {
  HidReportDescriptor descriptor;
  std::string error;
  REQUIRE(parseHidReportDescriptor(kPacked12.data(), kPacked12.size(), descriptor, error));
  CHECK(descriptor.usesReportIds);
  CHECK(descriptor.collections.size() == 3);
  CHECK(descriptor.collections[2].parent == 1);
  CHECK(descriptor.collections[2].usage == hidUsage(kHidPageGenericDesktop, 0x01));
  CHECK(descriptor.inputReportBytes(2) == 1 + 1 + 3 + 1);
  const HidMouseDecoder decoder = decoderFor(kPacked12);
  CHECK(decoder.mouseReportIds() == std::vector<uint8_t>{2});
  // dx = -5 = 0xffb, dy = 300 = 0x12c: bytes fb, (c << 4 | f), 12.
  const Bytes report = {0x02, 0x81, 0xfb, 0xcf, 0x12, 0xff};
  HidMouseDelta delta;
  REQUIRE(decoder.decode(report.data(), report.size(), delta));
  CHECK(delta.reportId == 2);
  CHECK(delta.buttons == 0x81);
  CHECK(delta.dxCounts == -5);
  CHECK(delta.dyCounts == 300);
  // -2047 and 2047.
  const Bytes limits = {0x02, 0x00, 0x01, 0xf8, 0x7f, 0x00};
  REQUIRE(decoder.decode(limits.data(), limits.size(), delta));
  CHECK(delta.dxCounts == -2047);
  CHECK(delta.dyCounts == 2047);
  // The vendor report (ID 5) is not a mouse report.
  const Bytes vendor = {0x05, 1, 2, 3, 4};
  CHECK_FALSE(decoder.decode(vendor.data(), vendor.size(), delta));
}

TEST_CASE("bit extraction at any offset and size with sign extension", "[hid]") {
  const uint8_t data[] = {0xb4, 0x5c, 0xf1, 0x0f};
  int64_t value = 0;
  REQUIRE(extractHidBits(data, 4, 0, 8, false, value));
  CHECK(value == 0xb4);
  REQUIRE(extractHidBits(data, 4, 0, 8, true, value));
  CHECK(value == -76);
  REQUIRE(extractHidBits(data, 4, 4, 12, false, value));
  CHECK(value == 0x5cb);
  REQUIRE(extractHidBits(data, 4, 3, 5, true, value));  // 10110 -> -10
  CHECK(value == -10);
  REQUIRE(extractHidBits(data, 4, 0, 32, true, value));
  CHECK(value == static_cast<int32_t>(0x0ff15cb4));
  CHECK_FALSE(extractHidBits(data, 4, 25, 8, false, value));
  CHECK_FALSE(extractHidBits(data, 4, 0, 33, false, value));
}

TEST_CASE("logical ranges, extended usages and button arrays", "[hid]") {
  // Unsigned maximum (min >= 0), a 4-byte usage with its own page, buttons as an array.
  const Bytes bytes = {0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x05, 0x09, 0x19, 0x00, 0x29, 0x05,
                       0x15, 0x00, 0x25, 0x05, 0x75, 0x04, 0x95, 0x02, 0x81, 0x00,  // two 4-bit button array slots
                       0x05, 0x02,  // another page; the X below names its own
                       0x0b, 0x30, 0x00, 0x01, 0x00, 0x0b, 0x31, 0x00, 0x01, 0x00, 0x15, 0x00,
                       0x26, 0xff, 0x00, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0xc0};
  HidReportDescriptor descriptor;
  std::string error;
  REQUIRE(parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error));
  REQUIRE(descriptor.fields.size() == 2);
  CHECK(descriptor.fields[1].logicalMax == 255);
  CHECK_FALSE(descriptor.fields[1].isSigned());
  CHECK(descriptor.fields[0].usages.size() == 6);
  const HidMouseDecoder decoder = decoderFor(bytes);
  HidMouseDelta delta;
  const Bytes report = {0x32, 0xff, 0x10};  // buttons 2 and 3 pressed, x = 255 (unsigned)
  REQUIRE(decoder.decode(report.data(), report.size(), delta));
  CHECK(delta.buttons == 0x6);
  CHECK(delta.dxCounts == 255);
  CHECK(delta.dyCounts == 16);
}

TEST_CASE("malformed descriptors give clear errors, not crashes", "[hid]") {
  std::string error;
  SECTION("truncated item") {
    Bytes cut(kBootMouse.begin(), kBootMouse.begin() + 39);  // inside "15 81"
    CHECK_FALSE(parses(cut, error));
    CHECK(error.find("truncated") != std::string::npos);
    CHECK(error.find("byte 38") != std::string::npos);
  }
  SECTION("collection not closed") {
    Bytes open(kBootMouse.begin(), kBootMouse.end() - 1);
    CHECK_FALSE(parses(open, error));
    CHECK(error.find("not closed") != std::string::npos);
  }
  SECTION("end collection without collection") {
    CHECK_FALSE(parses({0xc0}, error));
    CHECK(error.find("End Collection") != std::string::npos);
  }
  SECTION("pop without push, push too deep") {
    CHECK_FALSE(parses({0xb4}, error));
    CHECK(error.find("Pop") != std::string::npos);
    CHECK_FALSE(parses(Bytes(17, 0xa4), error));
    CHECK(error.find("Push") != std::string::npos);
  }
  SECTION("report ID 0, or after fields without one") {
    CHECK_FALSE(parses({0x85, 0x00}, error));
    CHECK(error.find("report ID") != std::string::npos);
    CHECK_FALSE(parses({0x75, 0x08, 0x95, 0x01, 0x81, 0x02, 0x85, 0x01}, error));
    CHECK(error.find("Report ID after") != std::string::npos);
  }
  SECTION("absurd sizes") {
    CHECK_FALSE(parses({0x76, 0x00, 0x10, 0x95, 0x01, 0x81, 0x02}, error));  // 4096-bit field
    CHECK_FALSE(parses({0x75, 0x20, 0x97, 0xff, 0xff, 0xff, 0x7f, 0x81, 0x02}, error));
    CHECK(error.find("4096") != std::string::npos);
  }
  SECTION("no mouse in it") {
    HidReportDescriptor descriptor;
    const Bytes keyboardish = {0x05, 0x07, 0x19, 0xe0, 0x29, 0xe7, 0x75, 0x01, 0x95, 0x08, 0x81, 0x02};
    REQUIRE(parseHidReportDescriptor(keyboardish.data(), keyboardish.size(), descriptor, error));
    HidMouseDecoder decoder;
    CHECK_FALSE(decoder.build(descriptor, error));
    CHECK(error.find("X or Y") != std::string::npos);
  }
  SECTION("random bytes never crash the parser or the decoder") {
    DeterministicRandom random(11);
    int parsed = 0;
    for (int trial = 0; trial < 20000; ++trial) {
      Bytes bytes(random.nextU64() % 48);
      for (auto& byte : bytes) byte = static_cast<uint8_t>(random.nextU64());
      HidReportDescriptor descriptor;
      if (!parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error)) {
        CHECK_FALSE(error.empty());
        continue;
      }
      ++parsed;
      HidMouseDecoder decoder;
      if (!decoder.build(descriptor, error)) continue;
      for (int i = 0; i < 8; ++i) {
        Bytes report(random.nextU64() % 16);
        for (auto& byte : report) byte = static_cast<uint8_t>(random.nextU64());
        HidMouseDelta delta;
        decoder.decode(report.data(), report.size(), delta);
      }
    }
    CHECK(parsed > 0);
  }
}
