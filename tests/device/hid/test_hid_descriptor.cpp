#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "hid/HidMouseDecoder.hpp"
#include "hid/HidReportDescriptor.hpp"
#include "recordings/HidRecorderFile.hpp"
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
  SECTION("report ID 0") {
    CHECK_FALSE(parses({0x85, 0x00}, error));
    CHECK(error.find("report ID") != std::string::npos);
  }
  SECTION("absurd sizes: the item's report is skipped, the descriptor kept") {
    for (const Bytes& bytes : {Bytes{0x76, 0x00, 0x10, 0x95, 0x01, 0x81, 0x02},  // a 4096-bit field
                               Bytes{0x75, 0x20, 0x97, 0xff, 0xff, 0xff, 0x7f, 0x81, 0x02}}) {
      HidReportDescriptor descriptor;
      REQUIRE(parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error));
      CHECK(descriptor.fields.empty());
      REQUIRE(descriptor.skipNotes.size() == 1);
      CHECK(descriptor.skipNotes[0].find("input report 0 skipped") != std::string::npos);
    }
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

namespace {
// Shaped like a wireless receiver's mouse interface: the mouse (ID 2: 16 buttons, 12-bit X/Y,
// wheel, AC pan), consumer control (ID 3) and system control (ID 4, null state) reports, a
// vendor protocol's short and long reports (IDs 0x10, 0x11, input and output) and the
// receiver's own (IDs 0x20, 0x21).
const Bytes kReceiver = {
    0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x85, 0x02, 0x09, 0x01, 0xa1, 0x00,                          // mouse, ID 2
    0x05, 0x09, 0x19, 0x01, 0x29, 0x10, 0x15, 0x00, 0x25, 0x01, 0x95, 0x10, 0x75, 0x01, 0x81, 0x02,  // 16 buttons
    0x05, 0x01, 0x16, 0x01, 0xf8, 0x26, 0xff, 0x07, 0x75, 0x0c, 0x95, 0x02, 0x09, 0x30, 0x09, 0x31,
    0x81, 0x06, 0x15, 0x81, 0x25, 0x7f, 0x75, 0x08, 0x95, 0x01, 0x09, 0x38, 0x81, 0x06,  // wheel
    0x05, 0x0c, 0x0a, 0x38, 0x02, 0x95, 0x01, 0x81, 0x06, 0xc0, 0xc0,                    // AC pan
    0x05, 0x0c, 0x09, 0x01, 0xa1, 0x01, 0x85, 0x03, 0x75, 0x10, 0x95, 0x02, 0x15, 0x01, 0x26, 0xff,
    0x02, 0x19, 0x01, 0x2a, 0xff, 0x02, 0x81, 0x00, 0xc0,  // consumer control, ID 3
    0x05, 0x01, 0x09, 0x80, 0xa1, 0x01, 0x85, 0x04, 0x75, 0x02, 0x95, 0x01, 0x15, 0x01, 0x25, 0x03,
    0x09, 0x82, 0x09, 0x81, 0x09, 0x83, 0x81, 0x60, 0x75, 0x06, 0x81, 0x03, 0xc0,  // system control, ID 4
    0x06, 0x00, 0xff, 0x09, 0x01, 0xa1, 0x01, 0x85, 0x10, 0x75, 0x08, 0x95, 0x06, 0x15, 0x00, 0x26,
    0xff, 0x00, 0x09, 0x01, 0x81, 0x00, 0x09, 0x01, 0x91, 0x00, 0xc0,  // vendor short, ID 0x10
    0x06, 0x00, 0xff, 0x09, 0x02, 0xa1, 0x01, 0x85, 0x11, 0x75, 0x08, 0x95, 0x13, 0x15, 0x00, 0x26,
    0xff, 0x00, 0x09, 0x02, 0x81, 0x00, 0x09, 0x02, 0x91, 0x00, 0xc0,  // vendor long, ID 0x11
    0x06, 0x00, 0xff, 0x09, 0x04, 0xa1, 0x01, 0x85, 0x20, 0x75, 0x08, 0x95, 0x0e, 0x15, 0x00, 0x26,
    0xff, 0x00, 0x09, 0x41, 0x81, 0x00, 0x09, 0x41, 0x91, 0x00, 0x85, 0x21, 0x95, 0x1f, 0x09, 0x42,
    0x81, 0x00, 0x09, 0x42, 0x91, 0x00, 0xc0};  // the receiver's, IDs 0x20 and 0x21

// A mouse (ID 1: 3 buttons, 8-bit X/Y) beside what it does not use and we cannot keep: a
// vendor feature report of 2048-bit elements (ID 5), a vendor input report whose second item
// has a usage minimum above its maximum (ID 6), a reserved main item tag, a reserved item type.
const Bytes kMouseBesideOddItems = {
    0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x85, 0x01, 0x09, 0x01, 0xa1, 0x00, 0x05, 0x09, 0x19, 0x01, 0x29, 0x03,
    0x15, 0x00, 0x25, 0x01, 0x95, 0x03, 0x75, 0x01, 0x81, 0x02, 0x95, 0x01, 0x75, 0x05, 0x81, 0x01, 0x05, 0x01,
    0x09, 0x30, 0x09, 0x31, 0x15, 0x81, 0x25, 0x7f, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0xc0, 0xc0,  // mouse
    0x06, 0x00, 0xff, 0x09, 0x01, 0xa1, 0x01,                                                        // vendor
    0x85, 0x05, 0x76, 0x00, 0x08, 0x95, 0x01, 0x09, 0x01, 0xb1, 0x02,                                // feature ID 5
    0x85, 0x06, 0x75, 0x08, 0x95, 0x01, 0x09, 0x02, 0x81, 0x02, 0x19, 0x05, 0x29, 0x02, 0x81, 0x02,  // input ID 6
    0xd0,                                                                                            // main tag 13
    0x0c,                                                                                            // item type 3
    0xc0};

HidMouseDelta decodeOk(const HidMouseDecoder& decoder, const Bytes& report) {
  HidMouseDelta delta;
  REQUIRE(decoder.decode(report.data(), report.size(), delta));
  return delta;
}

bool hasNote(const HidReportDescriptor& descriptor, const std::string& text) {
  for (const std::string& note : descriptor.skipNotes)
    if (note.find(text) != std::string::npos) return true;
  return false;
}
}  // namespace

TEST_CASE("a receiver's descriptor with many report IDs: only the mouse report is decoded", "[hid]") {
  HidReportDescriptor descriptor;
  std::string error;
  REQUIRE(parseHidReportDescriptor(kReceiver.data(), kReceiver.size(), descriptor, error));
  CHECK(descriptor.skippedItems == 0);
  CHECK(descriptor.inputReportBytes(2) == 8);
  CHECK(descriptor.inputReportBytes(0x11) == 20);
  const HidMouseDecoder decoder = decoderFor(kReceiver);
  CHECK(decoder.mouseReportIds() == std::vector<uint8_t>{2});
  // Buttons 1 and 16, dx = -3 = 0xffd, dy = 2047 = 0x7ff (at the limit).
  const HidMouseDelta delta = decodeOk(decoder, {0x02, 0x01, 0x80, 0xfd, 0xff, 0x7f, 0x00, 0x00});
  CHECK(delta.buttons == 0x8001);
  CHECK(delta.dxCounts == -3);
  CHECK(delta.dyCounts == 2047);
  CHECK(delta.saturated);
  HidMouseDelta other;
  for (const Bytes& report : {Bytes{0x03, 0xe9, 0x00, 0x00, 0x00}, Bytes{0x04, 0x01}, Bytes(20, 0x11)})
    CHECK_FALSE(decoder.decode(report.data(), report.size(), other));
}

TEST_CASE("a mouse that sends its buttons in a report of their own: decoded, not taken for another device's", "[hid]") {
  // The Xiaomi Mi Wireless Mouse receiver's layout (tests/data/hid/README.md): buttons, wheel and
  // AC pan in report 1, 12-bit X and Y in report 2, media keys in report 3 (another application).
  HidRecording split;
  std::string error;
  REQUIRE(readHidRecorderFile(std::string(KF_HID_DATA_DIR) + "/synthetic-250hz-split-buttons.hid", split, error));
  const HidMouseDecoder decoder = decoderFor(split.descriptor);
  CHECK(decoder.mouseReportIds() == std::vector<uint8_t>{1, 2});
  const HidMouseDelta buttons = decodeOk(decoder, {0x01, 0x05, 0x01, 0x00});  // left and middle, a wheel step
  CHECK(buttons.hasButtons);
  CHECK(buttons.buttons == 5);
  CHECK(buttons.dxCounts == 0);
  CHECK(buttons.dyCounts == 0);
  const HidMouseDelta motion = decodeOk(decoder, {0x02, 0xfd, 0x2f, 0x00});  // dx -3, dy 2
  CHECK_FALSE(motion.hasButtons);                                            // the buttons stay as report 1 left them
  CHECK(motion.dxCounts == -3);
  CHECK(motion.dyCounts == 2);
  HidMouseDelta keys;
  const Bytes report3 = {0x03, 0x01};
  CHECK_FALSE(decoder.decode(report3.data(), report3.size(), keys));

  // A gamepad's buttons beside a mouse (another application collection) are not the mouse's.
  const Bytes mouseAndGamepad = {
      0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x85, 0x01, 0x09, 0x01, 0xa1, 0x00, 0x05, 0x01, 0x09,
      0x30, 0x09, 0x31, 0x15, 0x81, 0x25, 0x7f, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0xc0, 0xc0,  // mouse: X, Y, ID 1
      0x05, 0x01, 0x09, 0x05, 0xa1, 0x01, 0x85, 0x02, 0x05, 0x09, 0x19, 0x01, 0x29, 0x08, 0x15,
      0x00, 0x25, 0x01, 0x75, 0x01, 0x95, 0x08, 0x81, 0x02, 0xc0};  // gamepad: 8 buttons, ID 2
  const HidMouseDecoder withGamepad = decoderFor(mouseAndGamepad);
  CHECK(withGamepad.mouseReportIds() == std::vector<uint8_t>{1});
  const Bytes gamepadReport = {0x02, 0xff};
  CHECK_FALSE(withGamepad.decode(gamepadReport.data(), gamepadReport.size(), keys));
  CHECK_FALSE(decodeOk(withGamepad, {0x01, 0x01, 0x02}).hasButtons);
}

TEST_CASE("what a mouse does not use is skipped, not refused", "[hid]") {
  HidReportDescriptor descriptor;
  std::string error;
  REQUIRE(parseHidReportDescriptor(kMouseBesideOddItems.data(), kMouseBesideOddItems.size(), descriptor, error));
  CHECK(descriptor.skippedItems == 4);
  CHECK(hasNote(descriptor, "report size 2048 too large: feature report 5 skipped"));
  CHECK(hasNote(descriptor, "bad usage minimum/maximum range: input report 6 skipped"));
  CHECK(hasNote(descriptor, "reserved main item tag 13 skipped"));
  CHECK(hasNote(descriptor, "reserved item type skipped"));
  for (const HidField& field : descriptor.fields) CHECK(field.reportId == 1);  // report 6's good item went too
  const HidMouseDecoder decoder = decoderFor(kMouseBesideOddItems);
  const HidMouseDelta delta = decodeOk(decoder, {0x01, 0x01, 0x05, 0xfb});
  CHECK(delta.buttons == 1);
  CHECK(delta.dxCounts == 5);
  CHECK(delta.dyCounts == -5);
  HidMouseDelta vendor;
  const Bytes report6 = {0x06, 0x00, 0x00};
  CHECK_FALSE(decoder.decode(report6.data(), report6.size(), vendor));

  // Fields before the first report ID stay in report 0 (as Linux reads them).
  const Bytes unnumberedFirst = {0x06, 0x00, 0xff, 0x09, 0x01, 0x75, 0x08, 0x95, 0x02, 0xb1, 0x02, 0x85, 0x01, 0x05,
                                 0x01, 0x09, 0x30, 0x09, 0x31, 0x15, 0x81, 0x25, 0x7f, 0x95, 0x02, 0x81, 0x06};
  REQUIRE(parseHidReportDescriptor(unnumberedFirst.data(), unnumberedFirst.size(), descriptor, error));
  CHECK(descriptor.fields[0].reportId == 0);
  CHECK(decoderFor(unnumberedFirst).mouseReportIds() == std::vector<uint8_t>{1});
}

TEST_CASE("a mouse report with an item beyond our bounds is refused with the reason", "[hid]") {
  Bytes bytes = kBootMouse;
  // Before X and Y (05 01 09 30 ...): a usage range from 0x31 down to 0x30.
  const Bytes badRange = {0x19, 0x31, 0x29, 0x30};
  bytes.insert(bytes.begin() + 34, badRange.begin(), badRange.end());
  HidReportDescriptor descriptor;
  std::string error;
  REQUIRE(parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error));
  HidMouseDecoder decoder;
  CHECK_FALSE(decoder.build(descriptor, error));
  CHECK(error.find("no relative Generic Desktop X or Y") != std::string::npos);
  CHECK(error.find("bad usage minimum/maximum range: input report 0 skipped") != std::string::npos);
}

TEST_CASE("saturation comes from each axis' logical limits within its field's bits", "[hid]") {
  // X 8 bits, logical -127..127; Y 16 bits, logical -32767..32767: 127 saturates X only.
  const Bytes mixed = {0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x09, 0x30, 0x15, 0x81, 0x25,
                       0x7f, 0x75, 0x08, 0x95, 0x01, 0x81, 0x06, 0x09, 0x31, 0x16, 0x01,
                       0x80, 0x26, 0xff, 0x7f, 0x75, 0x10, 0x95, 0x01, 0x81, 0x06, 0xc0};
  const HidMouseDecoder decoder = decoderFor(mixed);
  struct Case {
    Bytes report;
    int32_t dx, dy;
    bool saturated;
  };
  for (const Case& c : {Case{{0x7f, 0x7f, 0x00}, 127, 127, true}, Case{{0x7e, 0x7f, 0x00}, 126, 127, false},
                        Case{{0x7e, 0xff, 0x7f}, 126, 32767, true}, Case{{0x81, 0x00, 0x00}, -127, 0, true},
                        // beyond the logical range: clamped to it (as the kernel's input layer does)
                        Case{{0x80, 0x00, 0x00}, -127, 0, true}, Case{{0x00, 0x00, 0x80}, 0, -32767, true},
                        Case{{0x00, 0x02, 0x80}, 0, -32766, false}}) {
    INFO(c.dx << ", " << c.dy);
    const HidMouseDelta delta = decodeOk(decoder, c.report);
    CHECK(delta.dxCounts == c.dx);
    CHECK(delta.dyCounts == c.dy);
    CHECK(delta.saturated == c.saturated);
  }
  // A logical range wider than the field's 8 bits: the bits are the limit.
  const Bytes wide = {0x05, 0x01, 0x09, 0x30, 0x16, 0x01, 0x80, 0x26, 0xff, 0x7f, 0x75, 0x08, 0x95, 0x01, 0x81, 0x06};
  CHECK(decodeOk(decoderFor(wide), {0x7f}).saturated);
  CHECK(decodeOk(decoderFor(wide), {0x80}).saturated);
  CHECK_FALSE(decodeOk(decoderFor(wide), {0x7e}).saturated);
  // No logical range: unsigned, as Linux reads it; at rest (0) is never saturated.
  const Bytes none = {0x05, 0x01, 0x09, 0x30, 0x75, 0x08, 0x95, 0x01, 0x81, 0x06};
  CHECK(decodeOk(decoderFor(none), {0xff}).saturated);
  CHECK_FALSE(decodeOk(decoderFor(none), {0x00}).saturated);
  CHECK_FALSE(decodeOk(decoderFor(none), {0x01}).saturated);
  // 12-bit axes: 300 counts is not saturated (a guess of +-127 would say so); 2047 is.
  const HidMouseDecoder packed = decoderFor(kPacked12);
  CHECK_FALSE(decodeOk(packed, {0x02, 0x81, 0xfb, 0xcf, 0x12, 0xff}).saturated);
  CHECK(decodeOk(packed, {0x02, 0x00, 0x01, 0xf8, 0x7f, 0x00}).saturated);
  // A logical range the field's bits cannot hold (8 bits, -1000..-500: a broken descriptor)
  // keeps the bits' range, not an empty one (std::clamp with lowest > highest is undefined).
  const Bytes outside = {0x05, 0x01, 0x09, 0x30, 0x16, 0x18, 0xfc, 0x26,
                         0x0c, 0xfe, 0x75, 0x08, 0x95, 0x01, 0x81, 0x06};
  CHECK(decodeOk(decoderFor(outside), {0x64}).dxCounts == 100);
  CHECK_FALSE(decodeOk(decoderFor(outside), {0x64}).saturated);
  CHECK(decodeOk(decoderFor(outside), {0x80}).saturated);
}

TEST_CASE("the axes' range for evdev: the widest of the mouse reports'", "[hid]") {
  // Report 1: X, Y 8 bits (-127..127); report 2: X, Y 16 bits (-32767..32767). evdev cannot tell
  // which report a value came from: 127 from report 2 is no limit, so the range is report 2's.
  const Bytes twoReports = {0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x85, 0x01, 0x09, 0x30, 0x09, 0x31, 0x15, 0x81,
                            0x25, 0x7f, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0x85, 0x02, 0x09, 0x30, 0x09, 0x31,
                            0x16, 0x01, 0x80, 0x26, 0xff, 0x7f, 0x75, 0x10, 0x95, 0x02, 0x81, 0x06, 0xc0};
  int64_t xLo = 0, xHi = 0, yLo = 0, yHi = 0;
  REQUIRE(decoderFor(twoReports).axisRange(xLo, xHi, yLo, yHi));
  CHECK(xLo == -32767);
  CHECK(xHi == 32767);
  CHECK(yLo == -32767);
  CHECK(yHi == 32767);
  CHECK_FALSE(HidMouseDecoder().axisRange(xLo, xHi, yLo, yHi));
}
