#include "board/BoardProtocol.hpp"

#include <algorithm>

namespace kf::board {

namespace {

void put16(uint8_t* out, uint16_t value) {
  out[0] = static_cast<uint8_t>(value & 0xFF);
  out[1] = static_cast<uint8_t>(value >> 8);
}

uint16_t get16(const uint8_t* data) { return static_cast<uint16_t>(data[0] | (data[1] << 8)); }

// The last two bytes of a frame are the CRC of the bytes before them.
void sealFrame(uint8_t* frame, size_t size) { put16(frame + size - 2, crc16(frame, size - 2)); }

bool isSealed(const uint8_t* frame, size_t size) { return get16(frame + size - 2) == crc16(frame, size - 2); }

}  // namespace

uint16_t crc16(const uint8_t* data, size_t size) {
  uint16_t crc = 0xFFFF;
  for (size_t i = 0; i < size; ++i) {
    crc ^= static_cast<uint16_t>(data[i] << 8);
    for (int bit = 0; bit < 8; ++bit)
      crc = (crc & 0x8000) ? static_cast<uint16_t>((crc << 1) ^ 0x1021) : static_cast<uint16_t>(crc << 1);
  }
  return crc;
}

void encodeSetPoint(const SetPoint& setPoint, uint8_t* out) {
  out[0] = kSetPointType;
  out[1] = 0;  // flags, reserved: 0
  put16(out + 2, setPoint.sequence);
  put16(out + 4, setPoint.drive);
  sealFrame(out, kSetPointSize);
}

bool decodeSetPoint(const uint8_t* data, size_t size, SetPoint& out) {
  if (size != kSetPointSize || data[0] != kSetPointType || !isSealed(data, size)) return false;
  out.sequence = get16(data + 2);
  out.drive = get16(data + 4);
  return true;
}

void encodeMultiSetPoint(const MultiSetPoint& frame, uint8_t* out) {
  out[0] = kMultiSetPointType;
  out[1] = static_cast<uint8_t>(frame.count);
  put16(out + 2, frame.sequence);
  for (int i = 0; i < frame.count; ++i) put16(out + 4 + 2 * i, frame.drives[i]);
  sealFrame(out, multiSetPointSize(frame.count));
}

bool decodeAnySetPoint(const uint8_t* data, size_t size, MultiSetPoint& out) {
  if (size >= 1 && data[0] == kSetPointType) {
    SetPoint single;
    if (!decodeSetPoint(data, size, single)) return false;
    out.sequence = single.sequence;
    out.count = 1;
    out.drives[0] = single.drive;
    return true;
  }
  if (size < 2 || data[0] != kMultiSetPointType) return false;
  const int count = data[1];
  if (count < 1 || count > kMaxSubSetPoints || size != multiSetPointSize(count) || !isSealed(data, size)) return false;
  out.sequence = get16(data + 2);
  out.count = count;
  for (int i = 0; i < count; ++i) out.drives[i] = get16(data + 4 + 2 * i);
  return true;
}

void encodeStatus(const Status& status, uint8_t* out) {
  out[0] = kStatusType;
  out[1] = static_cast<uint8_t>(status.state);
  put16(out + 2, status.lastSequence);
  put16(out + 4, status.currentDrive);
  put16(out + 6, static_cast<uint16_t>(status.temperatureCentiC));
  put16(out + 8, status.errors);
  put16(out + 10, status.framesReceived);
  out[12] = status.framesRejected;
  out[13] = status.tickMs;
  sealFrame(out, kStatusSize);
}

bool decodeStatus(const uint8_t* data, size_t size, Status& out) {
  if (size != kStatusSize || data[0] != kStatusType || !isSealed(data, size)) return false;
  if (data[1] > static_cast<uint8_t>(BoardState::kFault)) return false;
  out.state = static_cast<BoardState>(data[1]);
  out.lastSequence = get16(data + 2);
  out.currentDrive = get16(data + 4);
  out.temperatureCentiC = static_cast<int16_t>(get16(data + 6));
  out.errors = get16(data + 8);
  out.framesReceived = get16(data + 10);
  out.framesRejected = data[12];
  out.tickMs = data[13];
  return true;
}

size_t versionReplySize(const VersionReply& version) {
  return version.protocolMinor == 0 ? kVersionSizeMinor0 : kVersionSize;
}

void encodeVersion(const VersionReply& version, uint8_t* out) {
  out[0] = version.protocolMajor;
  out[1] = version.protocolMinor;
  out[2] = version.firmwareMajor;
  out[3] = version.firmwareMinor;
  out[4] = version.firmwarePatch;
  out[5] = version.flags;
  put16(out + 6, version.fullScaleCurrentMa);
  if (versionReplySize(version) == kVersionSizeMinor0) return;
  out[8] = version.maxSubSetPoints;
  out[9] = 0;  // reserved
}

bool decodeVersion(const uint8_t* data, size_t size, VersionReply& out) {
  if (size != kVersionSizeMinor0 && size != kVersionSize) return false;
  out.protocolMajor = data[0];
  out.protocolMinor = data[1];
  out.firmwareMajor = data[2];
  out.firmwareMinor = data[3];
  out.firmwarePatch = data[4];
  out.flags = data[5];
  out.fullScaleCurrentMa = get16(data + 6);
  // A 2.0 board plays one set-point per frame; a 2.1 board's 0 would mean the same.
  out.maxSubSetPoints = size == kVersionSize ? std::max<uint8_t>(data[8], 1) : 1;
  return true;
}

void encodeClearReply(const ClearReply& reply, uint8_t* out) {
  put16(out, reply.before);
  put16(out + 2, reply.remaining);
}

bool decodeClearReply(const uint8_t* data, size_t size, ClearReply& out) {
  if (size != kClearReplySize) return false;
  out.before = get16(data);
  out.remaining = get16(data + 2);
  return true;
}

}  // namespace kf::board
