#include "board/BoardFirmware.hpp"

#include <algorithm>
#include <cmath>

namespace kf::board {

BoardFirmware::BoardFirmware(CoilDriver& coil, const VersionReply& version, double nowS)
    : coil_(coil), version_(version), temperatureC_(coil.temperatureC(nowS)) {}

void BoardFirmware::setDrive(uint16_t drive, double timeS, const char* why) {
  if (drive == drive_) return;
  drive_ = drive;
  coil_.setTarget(drive, timeS, why);
}

void BoardFirmware::turnOff(double timeS, const char* why) {
  subCount_ = subNext_ = 0;
  setDrive(0, timeS, why);
}

void BoardFirmware::playSubSetPoints(double nowS) {
  const double stepS = kFramePeriodS / subCount_;
  for (; subNext_ < subCount_; ++subNext_) {
    const double dueS = subStartS_ + subNext_ * stepS;
    if (dueS > nowS) return;
    // Each step checks what the frame's first did: armed, not over temperature.
    const bool mayDrive = state_ == BoardState::kArmed && !(errors_ & kErrOverTemperature);
    setDrive(mayDrive ? subDrives_[subNext_] : 0, dueS, "set-point");
  }
}

void BoardFirmware::advance(double nowS) {
  // The frame's steps come first (they end within a frame of its arrival), then the watchdog's
  // moment, each at its exact time.
  playSubSetPoints(nowS);
  if (watchdogPending_ && nowS >= lastValidS_ + kBoardWatchdogS) {
    const double fireS = lastValidS_ + kBoardWatchdogS;
    watchdogPending_ = false;
    if (state_ == BoardState::kArmed) errors_ |= kErrWatchdog;  // it only runs while armed
    turnOff(fireS, "watchdog");
  }
  // Over temperature is live: set while it lasts, the target held at 0.
  temperatureC_ = coil_.temperatureC(nowS);
  if (temperatureC_ > kOverTemperatureC) {
    errors_ |= kErrOverTemperature;
    turnOff(nowS, "over temperature");
  } else {
    errors_ &= static_cast<uint16_t>(~kErrOverTemperature);
  }
}

void BoardFirmware::receiveSetPoint(const uint8_t* data, size_t size, double nowS) {
  advance(nowS);
  MultiSetPoint setPoint;
  // A 2.0 board knows only the single set-point; a 2.1 board plays up to its announced count.
  const bool known =
      decodeAnySetPoint(data, size, setPoint) &&
      (data[0] == kSetPointType || (version_.protocolMinor >= 1 && setPoint.count <= version_.maxSubSetPoints));
  if (!known) {
    errors_ |= kErrBadFrame;
    ++rejectedFrames_;
    return;
  }
  if (haveSequence_ && !isNewerSequence(setPoint.sequence, lastSequence_)) {
    errors_ |= kErrStaleSequence;
    ++rejectedFrames_;
    return;
  }
  if (haveSequence_ && static_cast<uint16_t>(setPoint.sequence - lastSequence_) > 1) errors_ |= kErrSequenceGap;
  lastSequence_ = setPoint.sequence;
  haveSequence_ = true;
  ++validFrames_;
  // The watchdog runs while armed only: a disarmed board's target is 0 already (PROTOCOL.md 6).
  lastValidS_ = nowS;
  watchdogPending_ = state_ == BoardState::kArmed;
  // A newer frame replaces what is left of the one in play; its first step plays at once.
  std::copy(setPoint.drives, setPoint.drives + setPoint.count, subDrives_);
  subCount_ = setPoint.count;
  subNext_ = 0;
  subStartS_ = nowS;
  playSubSetPoints(nowS);
}

Status BoardFirmware::status(double nowS) {
  advance(nowS);
  Status status;
  status.state = state_;
  status.lastSequence = lastSequence_;
  status.currentDrive = drive_;
  status.temperatureCentiC = static_cast<int16_t>(std::lround(temperatureC_ * 100.0));
  status.errors = errors_;
  status.framesReceived = static_cast<uint16_t>(validFrames_);
  status.framesRejected = static_cast<uint8_t>(rejectedFrames_);
  status.tickMs = static_cast<uint8_t>(static_cast<int64_t>(std::floor(nowS * 1000.0)) & 0xFF);
  return status;
}

ControlReply BoardFirmware::control(uint8_t requestType, uint8_t request, uint16_t value, uint8_t* data,
                                    uint16_t length, double nowS) {
  advance(nowS);
  const ControlReply stall;
  const ControlReply done{false, 0};
  const bool in = (requestType & 0x80) != 0;
  if ((requestType & 0x7F) != 0x41) return stall;  // vendor, interface
  switch (static_cast<Request>(request)) {
    case Request::kGetVersion: {
      if (!in || length < kVersionSizeMinor0) return stall;
      // A 2.0 host asks for 8 bytes and gets them: the 2.1 field comes after.
      uint8_t reply[kVersionSize];
      encodeVersion(version_, reply);
      const auto size = static_cast<uint16_t>(std::min<size_t>(length, versionReplySize(version_)));
      std::copy(reply, reply + size, data);
      return {false, size};
    }
    case Request::kArm:
      if (in || value != kArmKey || refuseArm_ || state_ == BoardState::kFault || (errors_ & kErrOverTemperature))
        return stall;
      if (state_ == BoardState::kArmed) return done;  // ARM while armed: changes nothing
      state_ = BoardState::kArmed;
      haveSequence_ = false;     // the first frame after arming is taken whatever its sequence
      subCount_ = subNext_ = 0;  // the rest of a frame sent while disarmed never drives
      lastValidS_ = nowS;        // the watchdog starts with ARM
      watchdogPending_ = true;
      return done;
    case Request::kDisarm:
      if (in) return stall;
      state_ = BoardState::kDisarmed;
      watchdogPending_ = false;
      turnOff(nowS, "disarm");
      return done;
    case Request::kClearErrors: {
      if (!in || length < kClearReplySize) return stall;
      ClearReply reply;
      reply.before = errors_;
      // Latched flags go; a live condition that persists stays, and so does its fault.
      errors_ &= kErrOverTemperature | kErrSupply;
      if (overCurrentPresent_) errors_ |= kErrOverCurrent;
      if (state_ == BoardState::kFault && !overCurrentPresent_) state_ = BoardState::kDisarmed;
      reply.remaining = errors_;
      encodeClearReply(reply, data);
      return {false, kClearReplySize};
    }
  }
  return stall;
}

void BoardFirmware::usbReset(double nowS, const char* why) {
  advance(nowS);
  state_ = BoardState::kDisarmed;
  errors_ |= kErrUsbReset;
  watchdogPending_ = false;
  turnOff(nowS, why);
}

void BoardFirmware::overCurrent(double nowS, bool persists) {
  advance(nowS);
  state_ = BoardState::kFault;
  errors_ |= kErrOverCurrent;
  overCurrentPresent_ = persists;
  watchdogPending_ = false;
  turnOff(nowS, "over current");
}

void BoardFirmware::powerLoss(double nowS) {
  advance(nowS);
  state_ = BoardState::kDisarmed;
  watchdogPending_ = false;
  turnOff(nowS, "power");
}

void BoardFirmware::powerOn(double nowS) {
  advance(nowS);
  state_ = BoardState::kDisarmed;
  haveSequence_ = false;
  errors_ = kErrUsbReset;  // enumerated afresh: reported once, until the host's CLEAR_ERRORS
  overCurrentPresent_ = false;
  validFrames_ = rejectedFrames_ = 0;
  watchdogPending_ = false;
  subCount_ = subNext_ = 0;
}

}  // namespace kf::board
