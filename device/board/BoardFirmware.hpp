// BoardFirmware: the friction board's behaviour (device/board/PROTOCOL.md, sections 3 to 7) as a
// state machine on explicit times, apart from any transport: set-point validation and sequence
// rules, the sub-set-points of a multi set-point frame played at their own times, arming (and ARM while armed), the 20
// ms watchdog (idle while disarmed), status, error flags and CLEAR_ERRORS, the vendor control requests, USB reset,
// suspend, power loss and an over-current fault. One implementation, two transports: the emulator on the host
// (BoardEmulator inside EmulatedUsb, for the tests) and the FunctionFS gadget
// (device/board/gadget/, a reference firmware on any Linux board with a USB device port) feed
// it the same events. What it drives and senses is a CoilDriver: the emulator's simulated coil,
// or the gadget's PWM pin and temperature sensor. Not thread-safe: its transport serialises the
// calls. No allocation, no I/O.
#pragma once

#include <cstddef>
#include <cstdint>

#include "board/BoardProtocol.hpp"

namespace kf::board {

// What the firmware drives and senses: the current loop's target and the driver's temperature.
class CoilDriver {
 public:
  virtual ~CoilDriver() = default;
  // The coil current's target from timeS on (0: off); `why` names the cause ("set-point",
  // "watchdog", "disarm", "usb reset", ...). Called on changes only.
  virtual void setTarget(uint16_t drive, double timeS, const char* why) = 0;
  // The coil driver's temperature at nowS, in degC (a sensor's reading, or a model's).
  virtual double temperatureC(double nowS) = 0;
};

// A control request's outcome: STALL, or done with `length` bytes of data (IN requests).
struct ControlReply {
  bool stall = true;
  uint16_t length = 0;
};

class BoardFirmware {
 public:
  static constexpr double kOverTemperatureC = 80.0;  // at the driver: target 0 while above

  // `version` is what GET_VERSION answers (protocol, firmware, flags, full-scale current).
  BoardFirmware(CoilDriver& coil, const VersionReply& version, double nowS);

  // The board's own timers up to nowS: each sub-set-point of a multi set-point frame is played
  // at exactly its own time, the watchdog fires at exactly last valid + 20 ms (the coil's target
  // changes at those times), the over-temperature condition is read. A transport that plays
  // sub-set-points calls it at least once per sub-step (the gadget's tick; the emulator at
  // every event, with the exact times in the coil's timeline).
  void advance(double nowS);
  void receiveSetPoint(const uint8_t* data, size_t size, double nowS);
  Status status(double nowS);
  // A vendor request on EP 0 (bmRequestType, bRequest, wValue; wIndex is the interface's);
  // `data` holds `length` bytes: the reply of an IN request is written there.
  ControlReply control(uint8_t requestType, uint8_t request, uint16_t value, uint8_t* data, uint16_t length,
                       double nowS);
  void usbReset(double nowS, const char* why = "usb reset");  // bus reset, suspend, configuration 0
  void powerLoss(double nowS);                                // unplugged: everything off
  void powerOn(double nowS);                                  // plugged in again: a fresh, disarmed board

  // The current loop could not hold the current (a shorted coil): fault, target 0. `persists`:
  // the condition stays, so CLEAR_ERRORS leaves the board in fault until setOverCurrent(false).
  void overCurrent(double nowS, bool persists);
  void setOverCurrent(bool present) { overCurrentPresent_ = present; }
  // ARM is STALLed without a flag (a fault the board keeps; the emulator's failure mode).
  void setRefuseArm(bool refuse) { refuseArm_ = refuse; }
  void setProtocolMajor(uint8_t major) { version_.protocolMajor = major; }
  // A 2.0 board: an 8-byte version reply, multi set-point frames rejected as bad frames.
  void setProtocolMinor0() {
    version_.protocolMinor = 0;
    version_.maxSubSetPoints = 1;
  }

  // When the next level of the frame in play is due (s); negative when none is: a transport
  // that ticks slower than the levels wakes for it (the gadget's step timer).
  double nextStepS() const { return subNext_ < subCount_ ? subStartS_ + subNext_ * (kFramePeriodS / subCount_) : -1.0; }
  uint16_t drive() const { return drive_; }
  BoardState state() const { return state_; }
  uint16_t errors() const { return errors_; }
  uint64_t validFrames() const { return validFrames_; }
  uint64_t rejectedFrames() const { return rejectedFrames_; }

 private:
  void setDrive(uint16_t drive, double timeS, const char* why);
  // Plays the sub-set-points due by nowS, each at its own time.
  void playSubSetPoints(double nowS);
  // Target 0 and nothing more of the frame in play: every way the current goes off.
  void turnOff(double timeS, const char* why);

  CoilDriver& coil_;
  VersionReply version_;
  double temperatureC_;
  BoardState state_ = BoardState::kDisarmed;
  uint16_t drive_ = 0;
  uint16_t lastSequence_ = 0;
  bool haveSequence_ = false;
  double lastValidS_ = -1.0;
  bool watchdogPending_ = false;
  uint16_t errors_ = kErrUsbReset;  // a board starts enumerated: reported until CLEAR_ERRORS
  uint64_t validFrames_ = 0;
  uint64_t rejectedFrames_ = 0;
  // The frame in play: its drive levels, the next one to play, when the frame started.
  uint16_t subDrives_[kMaxSubSetPoints] = {};
  int subCount_ = 0;
  int subNext_ = 0;
  double subStartS_ = 0.0;
  bool refuseArm_ = false;
  bool overCurrentPresent_ = false;
};

}  // namespace kf::board
