#include <catch2/catch.hpp>
#include <cstring>

#include "board/BoardProtocol.hpp"

using namespace kf::board;

TEST_CASE("the CRC is CRC-16/CCITT-FALSE", "[board]") {
  const char* check = "123456789";
  CHECK(crc16(reinterpret_cast<const uint8_t*>(check), 9) == 0x29B1);
  CHECK(crc16(nullptr, 0) == 0xFFFF);
}

TEST_CASE("a set-point has the documented bytes and round-trips", "[board]") {
  uint8_t bytes[kSetPointSize];
  encodeSetPoint({1, 0x8000}, bytes);
  const uint8_t head[] = {0x01, 0x00, 0x01, 0x00, 0x00, 0x80};
  CHECK(std::memcmp(bytes, head, 6) == 0);
  const uint16_t crc = crc16(bytes, 6);
  CHECK(bytes[6] == (crc & 0xFF));
  CHECK(bytes[7] == (crc >> 8));
  for (int sequence : {0, 1, 0x7FFF, 0x8000, 0xFFFF})
    for (uint16_t drive : {uint16_t{0}, uint16_t{1}, uint16_t{12345}, kDriveFull}) {
      encodeSetPoint({static_cast<uint16_t>(sequence), drive}, bytes);
      SetPoint decoded;
      REQUIRE(decodeSetPoint(bytes, kSetPointSize, decoded));
      CHECK(decoded.sequence == sequence);
      CHECK(decoded.drive == drive);
    }
}

TEST_CASE("a damaged set-point is rejected: any bit, the length, the type", "[board]") {
  uint8_t bytes[kSetPointSize];
  encodeSetPoint({42, 30000}, bytes);
  SetPoint out;
  for (size_t bit = 0; bit < kSetPointSize * 8; ++bit) {
    uint8_t damaged[kSetPointSize];
    std::memcpy(damaged, bytes, kSetPointSize);
    damaged[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    CHECK_FALSE(decodeSetPoint(damaged, kSetPointSize, out));
  }
  CHECK_FALSE(decodeSetPoint(bytes, kSetPointSize - 1, out));
  CHECK_FALSE(decodeSetPoint(bytes, 0, out));
  uint8_t status[kStatusSize];
  encodeStatus({}, status);
  CHECK_FALSE(decodeSetPoint(status, kSetPointSize, out));
}

TEST_CASE("a status frame round-trips, negative temperatures too", "[board]") {
  Status status;
  status.state = BoardState::kArmed;
  status.lastSequence = 0xFFFE;
  status.currentDrive = 40000;
  status.temperatureCentiC = -1234;
  status.errors = kErrWatchdog | kErrSequenceGap;
  status.framesReceived = 65535;
  status.framesRejected = 255;
  status.tickMs = 200;
  uint8_t bytes[kStatusSize];
  encodeStatus(status, bytes);
  Status decoded;
  REQUIRE(decodeStatus(bytes, kStatusSize, decoded));
  CHECK(decoded.state == BoardState::kArmed);
  CHECK(decoded.lastSequence == 0xFFFE);
  CHECK(decoded.currentDrive == 40000);
  CHECK(decoded.temperatureCentiC == -1234);
  CHECK(decoded.errors == (kErrWatchdog | kErrSequenceGap));
  CHECK(decoded.framesReceived == 65535);
  CHECK(decoded.framesRejected == 255);
  CHECK(decoded.tickMs == 200);
  // A partial frame (a short IN transfer) and an unknown state are rejected.
  CHECK_FALSE(decodeStatus(bytes, kStatusSize - 2, decoded));
  bytes[1] = 7;
  encodeStatus(status, bytes);
  bytes[1] = 7;
  const uint16_t crc = crc16(bytes, kStatusSize - 2);
  bytes[14] = crc & 0xFF;
  bytes[15] = crc >> 8;
  CHECK_FALSE(decodeStatus(bytes, kStatusSize, decoded));
}

TEST_CASE("the version reply round-trips", "[board]") {
  VersionReply version;
  version.firmwareMajor = 2;
  version.firmwareMinor = 3;
  version.firmwarePatch = 4;
  version.flags = 1;
  version.fullScaleCurrentMa = 1500;
  uint8_t bytes[kVersionSize];
  encodeVersion(version, bytes);
  VersionReply decoded;
  REQUIRE(decodeVersion(bytes, kVersionSize, decoded));
  CHECK(decoded.protocolMajor == kProtocolMajor);
  CHECK(decoded.firmwarePatch == 4);
  CHECK(decoded.fullScaleCurrentMa == 1500);
  CHECK_FALSE(decodeVersion(bytes, 7, decoded));
}

TEST_CASE("sequence numbers compare across the wrap", "[board]") {
  CHECK(isNewerSequence(1, 0));
  CHECK(isNewerSequence(0, 0xFFFF));
  CHECK(isNewerSequence(0x7FFF, 0));
  CHECK_FALSE(isNewerSequence(0x8000, 0));
  CHECK_FALSE(isNewerSequence(5, 5));
  CHECK_FALSE(isNewerSequence(4, 5));
}
