// BoardEmulator: the emulator's board, the board's firmware (BoardFirmware, the same code the
// FunctionFS gadget runs) driving a simulated coil: a timeline of its current for tests ("when
// did the magnet go off") and a heat model for its temperature. It does not model the current
// loop or its PWM: its current is the target at once. Control requests answer as libusb would
// (usb::Result). Not thread-safe: EmulatedUsb locks it.
#pragma once

#include <cstdint>
#include <vector>

#include "board/BoardFirmware.hpp"
#include "board/UsbPort.hpp"

namespace kf::board {

// The coil the emulated firmware drives: every change of its target, and its temperature from
// the mean square drive (time constant 5 s, full drive for ever: ambient + 60 degC).
class SimulatedCoil : public CoilDriver {
 public:
  struct Change {
    double timeS;
    uint16_t drive;   // the coil current target from then on
    const char* why;  // "set-point", "watchdog", "disarm", "usb reset", "power"...
  };

  void setTarget(uint16_t drive, double timeS, const char* why) override;
  double temperatureC(double nowS) override;
  void setAmbientC(double ambientC) { ambientC_ = ambientC; }
  const std::vector<Change>& timeline() const { return timeline_; }

 private:
  void heatTo(double nowS);

  uint16_t drive_ = 0;
  double timeS_ = 0.0;
  double ambientC_ = 25.0;
  double heat_ = 0.0;  // mean (drive / full)^2
  std::vector<Change> timeline_;
};

// Base-from-member: the coil is made before the firmware that drives it.
struct SimulatedCoilHolder {
  SimulatedCoil coil;
};

class BoardEmulator : private SimulatedCoilHolder, public BoardFirmware {
 public:
  using Change = SimulatedCoil::Change;

  explicit BoardEmulator(double nowS = 0.0);

  // A vendor request on EP 0, as libusb reports it: kPipe (STALL) for unknown ones and refused ARMs.
  usb::Result control(uint8_t requestType, uint8_t request, uint16_t value, uint8_t* data, uint16_t length,
                      int* transferred, double nowS);
  void setAmbientC(double ambientC) { coil.setAmbientC(ambientC); }
  double temperatureC(double nowS) { return coil.temperatureC(nowS); }
  const std::vector<Change>& timeline() const { return coil.timeline(); }
  // The first time at or after fromS that the coil current went to 0; negative when it has not.
  double offTimeAfter(double fromS) const;
};

}  // namespace kf::board
