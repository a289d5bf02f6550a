#include "board/BoardEmulator.hpp"

#include <cmath>

namespace kf::board {

namespace {
constexpr double kHeatTimeConstantS = 5.0;
constexpr double kDegreesAtFullHeat = 60.0;  // full drive for ever: ambient + 60 degC
constexpr double kOverTemperatureC = 80.0;
}  // namespace

BoardEmulator::BoardEmulator(double nowS) : timeS_(nowS) {}

void BoardEmulator::setDrive(uint16_t drive, double timeS, const char* why) {
  if (drive == drive_) return;
  drive_ = drive;
  timeline_.push_back({timeS, drive, why});
}

void BoardEmulator::heatTo(double nowS) {
  if (nowS <= timeS_) return;
  const double level = static_cast<double>(drive_) / kDriveFull;
  heat_ += (level * level - heat_) * (1.0 - std::exp(-(nowS - timeS_) / kHeatTimeConstantS));
  temperatureC_ = ambientC_ + kDegreesAtFullHeat * heat_;
  timeS_ = nowS;
  if (temperatureC_ > kOverTemperatureC) {
    errors_ |= kErrOverTemperature;
    setDrive(0, nowS, "over temperature");
  } else {
    errors_ &= static_cast<uint16_t>(~kErrOverTemperature);
  }
}

void BoardEmulator::advance(double nowS) {
  // The watchdog's moment comes first, at its exact time.
  if (watchdogPending_ && nowS >= lastValidS_ + kBoardWatchdogS) {
    const double fireS = lastValidS_ + kBoardWatchdogS;
    heatTo(fireS);
    watchdogPending_ = false;
    if (state_ == BoardState::kArmed) errors_ |= kErrWatchdog;  // it only runs while armed
    setDrive(0, fireS, "watchdog");
  }
  heatTo(nowS);
}

void BoardEmulator::receiveSetPoint(const uint8_t* data, size_t size, double nowS) {
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

Status BoardEmulator::status(double nowS) {
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

usb::Result BoardEmulator::control(uint8_t requestType, uint8_t request, uint16_t value, uint8_t* data, uint16_t length,
                                   int* transferred, double nowS) {
  advance(nowS);
  if (transferred != nullptr) *transferred = 0;
  const bool in = (requestType & 0x80) != 0;
  if ((requestType & 0x7F) != 0x41) return usb::Result::kPipe;  // vendor, interface
  switch (static_cast<Request>(request)) {
    case Request::kGetVersion: {
      if (!in || length < kVersionSize) return usb::Result::kPipe;
      VersionReply version;
      version.protocolMajor = protocolMajor_;
      version.firmwareMajor = 1;
      version.flags = 1;  // measures the current
      version.fullScaleCurrentMa = 1500;
      encodeVersion(version, data);
      if (transferred != nullptr) *transferred = kVersionSize;
      return usb::Result::kOk;
    }
    case Request::kArm:
      if (in || value != kArmKey || refuseArm_ || state_ == BoardState::kFault || (errors_ & kErrOverTemperature))
        return usb::Result::kPipe;
      if (state_ == BoardState::kArmed) return usb::Result::kOk;  // ARM while armed: changes nothing
      state_ = BoardState::kArmed;
      haveSequence_ = false;  // the first frame after arming is taken whatever its sequence
      lastValidS_ = nowS;     // the watchdog starts with ARM
      watchdogPending_ = true;
      return usb::Result::kOk;
    case Request::kDisarm:
      if (in) return usb::Result::kPipe;
      state_ = BoardState::kDisarmed;
      setDrive(0, nowS, "disarm");
      return usb::Result::kOk;
    case Request::kClearErrors: {
      if (!in || length < kClearReplySize) return usb::Result::kPipe;
      ClearReply reply;
      reply.before = errors_;
      // Latched flags go; a live condition that persists stays, and so does its fault.
      errors_ &= kErrOverTemperature | kErrSupply;
      if (overCurrentPresent_) errors_ |= kErrOverCurrent;
      if (state_ == BoardState::kFault && !overCurrentPresent_) state_ = BoardState::kDisarmed;
      reply.remaining = errors_;
      encodeClearReply(reply, data);
      if (transferred != nullptr) *transferred = kClearReplySize;
      return usb::Result::kOk;
    }
  }
  return usb::Result::kPipe;
}

void BoardEmulator::usbReset(double nowS, const char* why) {
  advance(nowS);
  state_ = BoardState::kDisarmed;
  errors_ |= kErrUsbReset;
  watchdogPending_ = false;
  setDrive(0, nowS, why);
}

void BoardEmulator::overCurrent(double nowS, bool persists) {
  advance(nowS);
  state_ = BoardState::kFault;
  errors_ |= kErrOverCurrent;
  overCurrentPresent_ = persists;
  watchdogPending_ = false;
  setDrive(0, nowS, "over current");
}

void BoardEmulator::powerLoss(double nowS) {
  advance(nowS);
  state_ = BoardState::kDisarmed;
  watchdogPending_ = false;
  setDrive(0, nowS, "power");
}

void BoardEmulator::powerOn(double nowS) {
  advance(nowS);
  state_ = BoardState::kDisarmed;
  haveSequence_ = false;
  errors_ = kErrUsbReset;  // enumerated afresh: reported once, until the host's CLEAR_ERRORS
  overCurrentPresent_ = false;
  validFrames_ = rejectedFrames_ = 0;
  watchdogPending_ = false;
}

double BoardEmulator::offTimeAfter(double fromS) const {
  for (const Change& change : timeline_)
    if (change.timeS >= fromS && change.drive == 0) return change.timeS;
  return -1.0;
}

}  // namespace kf::board
