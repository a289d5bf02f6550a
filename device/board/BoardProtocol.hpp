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
constexpr uint8_t kProtocolMajor = 2;  // a host refuses a board of another major version
constexpr uint8_t kProtocolMinor = 0;

constexpr int kInterfaceNumber = 0;
constexpr uint8_t kInterfaceClass = 0xFF;     // vendor specific
constexpr uint8_t kInterfaceSubclass = 0x4B;  // "K"
constexpr uint8_t kInterfaceProtocol = 0x01;
constexpr uint8_t kSetPointEndpoint = 0x01;  // interrupt OUT, bInterval 1 (1 ms, full speed)
constexpr uint8_t kStatusEndpoint = 0x81;    // interrupt IN, bInterval 1
constexpr double kBoardWatchdogS = 0.020;    // the board: no valid set-point this long -> off

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
constexpr size_t kVersionSize = 8;
constexpr size_t kClearReplySize = 4;
constexpr uint8_t kSetPointType = 0x01;
constexpr uint8_t kStatusType = 0x81;

struct SetPoint {
  uint16_t sequence = 0;  // +1 per frame, wraps; the board takes only newer ones
  uint16_t drive = 0;     // 0..kDriveFull
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

void encodeStatus(const Status& status, uint8_t* out);  // kStatusSize bytes
bool decodeStatus(const uint8_t* data, size_t size, Status& out);

void encodeVersion(const VersionReply& version, uint8_t* out);  // kVersionSize bytes
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
