#include "board/BoardFirmware.hpp"

#include <cmath>

namespace kf::board {

BoardFirmware::BoardFirmware(CoilDriver& coil, const VersionReply& version, double nowS)
    : coil_(coil), version_(version), temperatureC_(coil.temperatureC(nowS)) {}

void BoardFirmware::setDrive(uint16_t drive, double timeS, const char* why) {
  if (drive == drive_) return;
  drive_ = drive;
  coil_.setTarget(drive, timeS, why);
}

void BoardFirmware::advance(double nowS) {
  // The watchdog's moment comes first, at its exact time.
  if (watchdogPending_ && nowS >= lastValidS_ + kBoardWatchdogS) {
    const double fireS = lastValidS_ + kBoardWatchdogS;
    watchdogPending_ = false;
    if (state_ == BoardState::kArmed) errors_ |= kErrWatchdog;  // it only runs while armed
    setDrive(0, fireS, "watchdog");
  }
  // Over temperature is live: set while it lasts, the target held at 0.
  temperatureC_ = coil_.temperatureC(nowS);
  if (temperatureC_ > kOverTemperatureC) {
    errors_ |= kErrOverTemperature;
    setDrive(0, nowS, "over temperature");
  } else {
    errors_ &= static_cast<uint16_t>(~kErrOverTemperature);
  }
}

void BoardFirmware::receiveSetPoint(const uint8_t* data, size_t size, double nowS) {
  advance(nowS);
  SetPoint setPoint;
  if (!decodeSetPoint(data, size, setPoint)) {
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
  const bool mayDrive = state_ == BoardState::kArmed && !(errors_ & kErrOverTemperature);
  setDrive(mayDrive ? setPoint.drive : 0, nowS, "set-point");
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
    case Request::kGetVersion:
      if (!in || length < kVersionSize) return stall;
      encodeVersion(version_, data);
      return {false, kVersionSize};
    case Request::kArm:
      if (in || value != kArmKey || refuseArm_ || state_ == BoardState::kFault || (errors_ & kErrOverTemperature))
        return stall;
      if (state_ == BoardState::kArmed) return done;  // ARM while armed: changes nothing
      state_ = BoardState::kArmed;
      haveSequence_ = false;  // the first frame after arming is taken whatever its sequence
      lastValidS_ = nowS;     // the watchdog starts with ARM
      watchdogPending_ = true;
      return done;
    case Request::kDisarm:
      if (in) return stall;
      state_ = BoardState::kDisarmed;
      watchdogPending_ = false;
      setDrive(0, nowS, "disarm");
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
  setDrive(0, nowS, why);
}

void BoardFirmware::overCurrent(double nowS, bool persists) {
  advance(nowS);
  state_ = BoardState::kFault;
  errors_ |= kErrOverCurrent;
  overCurrentPresent_ = persists;
  watchdogPending_ = false;
  setDrive(0, nowS, "over current");
}

void BoardFirmware::powerLoss(double nowS) {
  advance(nowS);
  state_ = BoardState::kDisarmed;
  watchdogPending_ = false;
  setDrive(0, nowS, "power");
}

void BoardFirmware::powerOn(double nowS) {
  advance(nowS);
  state_ = BoardState::kDisarmed;
  haveSequence_ = false;
  errors_ = kErrUsbReset;  // enumerated afresh: reported once, until the host's CLEAR_ERRORS
  overCurrentPresent_ = false;
  validFrames_ = rejectedFrames_ = 0;
  watchdogPending_ = false;
}

}  // namespace kf::board
