#include "board/BoardEmulator.hpp"

#include <cmath>

namespace kf::board {

namespace {
constexpr double kHeatTimeConstantS = 5.0;
constexpr double kDegreesAtFullHeat = 60.0;  // full drive for ever: ambient + 60 degC

// What the emulated board answers to GET_VERSION: it measures its current, 1.5 A full scale.
VersionReply emulatedVersion() {
  VersionReply version;
  version.firmwareMajor = 1;
  version.flags = 1;
  version.fullScaleCurrentMa = 1500;
  version.maxSubSetPoints = kMaxSubSetPoints;  // its coil's target changes at the exact times
  return version;
}
}  // namespace

void SimulatedCoil::heatTo(double nowS) {
  if (nowS <= timeS_) return;
  const double level = static_cast<double>(drive_) / kDriveFull;
  heat_ += (level * level - heat_) * (1.0 - std::exp(-(nowS - timeS_) / kHeatTimeConstantS));
  timeS_ = nowS;
}

void SimulatedCoil::setTarget(uint16_t drive, double timeS, const char* why) {
  heatTo(timeS);
  drive_ = drive;
  timeline_.push_back({timeS, drive, why});
}

double SimulatedCoil::temperatureC(double nowS) {
  heatTo(nowS);
  return ambientC_ + kDegreesAtFullHeat * heat_;
}

BoardEmulator::BoardEmulator(double nowS) : BoardFirmware(coil, emulatedVersion(), nowS) {}

usb::Result BoardEmulator::control(uint8_t requestType, uint8_t request, uint16_t value, uint8_t* data, uint16_t length,
                                   int* transferred, double nowS) {
  const ControlReply reply = BoardFirmware::control(requestType, request, value, data, length, nowS);
  if (transferred != nullptr) *transferred = reply.stall ? 0 : reply.length;
  return reply.stall ? usb::Result::kPipe : usb::Result::kOk;
}

double BoardEmulator::offTimeAfter(double fromS) const {
  for (const Change& change : coil.timeline())
    if (change.timeS >= fromS && change.drive == 0) return change.timeS;
  return -1.0;
}

}  // namespace kf::board
