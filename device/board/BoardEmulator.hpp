// BoardEmulator: the friction board of device/board/PROTOCOL.md as a state machine on explicit
// times — set-point validation, sequence rules, arming (and ARM while armed), the 20 ms
// watchdog (idle while disarmed), USB reset / suspend / power loss, CLEAR_ERRORS, an
// over-current fault, a coil heat and temperature model — with a timeline of the coil current
// for tests ("when did the magnet go off"). It does not model the current loop or its PWM:
// its current is the target at once. Not thread-safe: EmulatedUsb locks it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "board/BoardProtocol.hpp"
#include "board/UsbPort.hpp"

namespace kf::board {

class BoardEmulator {
 public:
  struct Change {
    double timeS;
    uint16_t drive;   // the coil current target from then on
    const char* why;  // "set-point", "watchdog", "disarm", "usb reset", "power"...
  };

  explicit BoardEmulator(double nowS = 0.0);

  // The board's own timers up to nowS: the watchdog fires at exactly last valid + 20 ms.
  void advance(double nowS);
  void receiveSetPoint(const uint8_t* data, size_t size, double nowS);
  Status status(double nowS);
  // A vendor request on EP 0. kPipe (STALL) for unknown ones and refused ARMs.
  usb::Result control(uint8_t requestType, uint8_t request, uint16_t value, uint8_t* data, uint16_t length,
                      int* transferred, double nowS);
  void usbReset(double nowS, const char* why = "usb reset");  // bus reset or suspend: off, disarmed
  void powerLoss(double nowS);                                // unplugged: everything off and forgotten
  void powerOn(double nowS);                                  // plugged in again: a fresh, disarmed board

  // Failure modes: ARM is refused (a fault the board keeps, no coil supply).
  void setRefuseArm(bool refuse) { refuseArm_ = refuse; }
  // The loop cannot hold the current (a shorted coil): fault, current off. `persists`: the
  // condition stays, so CLEAR_ERRORS leaves the board in fault until setOverCurrent(false).
  void overCurrent(double nowS, bool persists);
  void setOverCurrent(bool present) { overCurrentPresent_ = present; }
  void setAmbientC(double ambientC) { ambientC_ = ambientC; }
  void setProtocolMajor(uint8_t major) { protocolMajor_ = major; }

  uint16_t drive() const { return drive_; }
  BoardState state() const { return state_; }
  uint16_t errors() const { return errors_; }
  uint64_t validFrames() const { return validFrames_; }
  uint64_t rejectedFrames() const { return rejectedFrames_; }
  double temperatureC() const { return temperatureC_; }
  const std::vector<Change>& timeline() const { return timeline_; }
  // The first time at or after fromS that the coil current went to 0; negative when it has not.
  double offTimeAfter(double fromS) const;

 private:
  void setDrive(uint16_t drive, double timeS, const char* why);
  void heatTo(double nowS);

  double timeS_;
  BoardState state_ = BoardState::kDisarmed;
  uint16_t drive_ = 0;
  uint16_t lastSequence_ = 0;
  bool haveSequence_ = false;
  double lastValidS_ = -1.0;
  bool watchdogPending_ = false;
  uint16_t errors_ = kErrUsbReset;  // a board starts enumerated: reported until CLEAR_ERRORS
  uint64_t validFrames_ = 0;
  uint64_t rejectedFrames_ = 0;
  bool refuseArm_ = false;
  bool overCurrentPresent_ = false;
  uint8_t protocolMajor_ = kProtocolMajor;
  double ambientC_ = 25.0;
  double heat_ = 0.0;  // mean (drive / full)^2, time constant 5 s
  double temperatureC_ = 25.0;
  std::vector<Change> timeline_;
};

}  // namespace kf::board
