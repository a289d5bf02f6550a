// BoardProtocol: the wire format of the friction board's USB protocol (device/board/PROTOCOL.md):
// the set-point OUT frame, the status IN frame, the version reply, the vendor control
// requests and the CRC that guards each frame. Pure C++: no libusb, no I/O, no allocation.
// Multi-byte fields are little-endian on the wire whatever the host.
#pragma once

#include <cstddef>
#include <cstdint>

namespace kf::board {

// Placeholder IDs from the pid.codes test range (1209:0001..0010 are for private testing
// only). A board that leaves the lab needs its own PID: change these and the udev rule.
// Another device may carry the same test IDs: the host only touches one whose interface 0 is
// the board's (kInterfaceClass/Subclass/Protocol) and answers GET_VERSION (PROTOCOL.md 1).
constexpr uint16_t kVendorId = 0x1209;
constexpr uint16_t kProductId = 0x0001;

// 2.0: CLEAR_ERRORS became an IN request that answers what it cleared and what persists.
// 2.1: the multi set-point frame (several drive levels per 1 ms frame, PROTOCOL.md 3.1) and the
// version reply's field saying how many a board plays.
constexpr uint8_t kProtocolMajor = 2;  // a host refuses a board of another major version
constexpr uint8_t kProtocolMinor = 1;

constexpr int kInterfaceNumber = 0;
constexpr uint8_t kInterfaceClass = 0xFF;     // vendor specific
constexpr uint8_t kInterfaceSubclass = 0x4B;  // "K"
constexpr uint8_t kInterfaceProtocol = 0x01;
constexpr uint8_t kSetPointEndpoint = 0x01;  // interrupt OUT, bInterval 1 (1 ms, full speed)
constexpr uint8_t kStatusEndpoint = 0x81;    // interrupt IN, bInterval 1
constexpr double kBoardWatchdogS = 0.020;    // the board: no valid set-point this long -> off
constexpr double kFramePeriodS = 0.001;      // one set-point frame per full-speed USB frame

constexpr uint16_t kDriveFull = 65535;  // drive level: 0 = no current .. 65535 = full scale

// Vendor requests, bmRequestType 0x41 (OUT) or 0xC1 (IN): vendor, recipient interface,
// wIndex = kInterfaceNumber.
enum class Request : uint8_t {
  kGetVersion = 0x01,   // IN, 8 bytes: VersionReply
  kArm = 0x02,          // OUT, wValue = kArmKey, no data
  kDisarm = 0x03,       // OUT, no data
  kClearErrors = 0x04,  // IN, 4 bytes: ClearReply; clears the latched error flags
};
constexpr uint16_t kArmKey = 0x4B46;  // "KF": a stray request does not arm the magnet

enum class BoardState : uint8_t { kDisarmed = 0, kArmed = 1, kFault = 2 };

// Error flags of the status frame; latched until kClearErrors, except the live ones noted.
// kLiveErrors: the conditions CLEAR_ERRORS cannot clear while they last.
enum ErrorFlag : uint16_t {
  kErrWatchdog = 1u << 0,         // no valid set-point for kBoardWatchdogS: current was turned off
  kErrBadFrame = 1u << 1,         // a set-point failed its length, type or CRC check
  kErrStaleSequence = 1u << 2,    // a set-point's sequence was not newer than the last one
  kErrOverTemperature = 1u << 3,  // live: coil or driver too hot; drive limited to 0 until cool
  kErrOverCurrent = 1u << 4,      // the current exceeded its limit; board went to kFault
  kErrSupply = 1u << 5,           // coil supply below its minimum
  kErrUsbReset = 1u << 6,         // power-on, bus reset or suspend since the last CLEAR_ERRORS
  kErrSequenceGap = 1u << 7,      // set-points were lost (a sequence jumped by more than 1)
};
constexpr uint16_t kLiveErrors = kErrOverTemperature | kErrOverCurrent | kErrSupply;

constexpr size_t kSetPointSize = 8;
constexpr size_t kStatusSize = 16;
constexpr size_t kVersionSize = 10;       // 2.1's reply; a 2.0 board answers the first 8 bytes
constexpr size_t kVersionSizeMinor0 = 8;  // what a 2.0 board answers
constexpr size_t kClearReplySize = 4;
constexpr uint8_t kSetPointType = 0x01;
constexpr uint8_t kMultiSetPointType = 0x02;  // 2.1
constexpr uint8_t kStatusType = 0x81;

// The multi set-point frame (2.1): `count` drive levels, each played for kFramePeriodS / count,
// the first at once. 8 at full speed: 125 us steps, 8 kHz, in a 22-byte packet.
constexpr int kMaxSubSetPoints = 8;
constexpr size_t multiSetPointSize(int count) { return 6 + 2 * static_cast<size_t>(count); }
constexpr size_t kMaxSetPointFrameSize = multiSetPointSize(kMaxSubSetPoints);

struct SetPoint {
  uint16_t sequence = 0;  // +1 per frame, wraps; the board takes only newer ones
  uint16_t drive = 0;     // 0..kDriveFull
};

// A set-point frame of either type: a single set-point is a frame of count 1.
struct MultiSetPoint {
  uint16_t sequence = 0;
  int count = 1;                           // 1..kMaxSubSetPoints
  uint16_t drives[kMaxSubSetPoints] = {};  // oldest first
};

struct Status {
  BoardState state = BoardState::kDisarmed;
  uint16_t lastSequence = 0;      // of the last set-point the board applied
  uint16_t currentDrive = 0;      // measured coil current, in drive units
  int16_t temperatureCentiC = 0;  // driver/coil temperature, 0.01 degC
  uint16_t errors = 0;            // ErrorFlag bits
  uint16_t framesReceived = 0;    // valid set-points, wraps
  uint8_t framesRejected = 0;     // bad or stale set-points, wraps
  uint8_t tickMs = 0;             // the board's 1 ms counter, wraps: orders status frames
};

struct VersionReply {
  uint8_t protocolMajor = kProtocolMajor;
  uint8_t protocolMinor = kProtocolMinor;
  uint8_t firmwareMajor = 0;
  uint8_t firmwareMinor = 0;
  uint8_t firmwarePatch = 0;
  uint8_t flags = 0;                // bit 0: the board measures current (else currentDrive echoes)
  uint16_t fullScaleCurrentMa = 0;  // current at kDriveFull
  uint8_t maxSubSetPoints = 1;      // 2.1: most drive levels per frame the board plays (2.0: 1)
};

// The answer to CLEAR_ERRORS: the flags as they were, and those still set after clearing (the
// live conditions that persist: over temperature, over current, supply). A board still in
// fault answers kErrOverCurrent in `remaining`.
struct ClearReply {
  uint16_t before = 0;
  uint16_t remaining = 0;
};

// CRC-16/CCITT-FALSE: polynomial 0x1021, initial 0xFFFF, no reflection, no final xor
// ("123456789" -> 0x29B1). Cheap in firmware with or without a table.
uint16_t crc16(const uint8_t* data, size_t size);

void encodeSetPoint(const SetPoint& setPoint, uint8_t* out);  // kSetPointSize bytes
// False when size, type or CRC is wrong.
bool decodeSetPoint(const uint8_t* data, size_t size, SetPoint& out);
// multiSetPointSize(frame.count) bytes; count must be 1..kMaxSubSetPoints.
void encodeMultiSetPoint(const MultiSetPoint& frame, uint8_t* out);
// Either type (a single set-point as count 1). False when the size does not match the type and
// count, the count is not 1..kMaxSubSetPoints, or the CRC is wrong.
bool decodeAnySetPoint(const uint8_t* data, size_t size, MultiSetPoint& out);

void encodeStatus(const Status& status, uint8_t* out);  // kStatusSize bytes
bool decodeStatus(const uint8_t* data, size_t size, Status& out);

// versionReplySize(version) bytes: 8 for a 2.0 board (minor 0), kVersionSize from 2.1 on.
size_t versionReplySize(const VersionReply& version);
void encodeVersion(const VersionReply& version, uint8_t* out);
// 8 bytes (2.0: maxSubSetPoints 1) or kVersionSize.
bool decodeVersion(const uint8_t* data, size_t size, VersionReply& out);

void encodeClearReply(const ClearReply& reply, uint8_t* out);  // kClearReplySize bytes
bool decodeClearReply(const uint8_t* data, size_t size, ClearReply& out);

// True when `sequence` is newer than `last` in 16-bit serial number arithmetic (RFC 1982):
// 1..32767 steps ahead.
inline bool isNewerSequence(uint16_t sequence, uint16_t last) {
  const uint16_t ahead = static_cast<uint16_t>(sequence - last);
  return ahead != 0 && ahead < 0x8000;
}

}  // namespace kf::board
