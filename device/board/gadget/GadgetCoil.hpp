// GadgetCoil: what the gadget's firmware drives and senses on a Linux board. The coil current's
// target goes to a PWM pin through the kernel's sysfs PWM class (duty cycle = drive / 65535 of
// the period): filtered to a voltage, it is the set-point of a current source such as the one
// of docs/current-source.md (PROTOCOL.md, "The gadget"). The temperature comes from a sysfs
// file in millidegrees C (hwmon's temp*_input, a thermal zone's temp) on the coil's driver.
// Without a PWM pin the target is only logged; without a sensor the temperature reads a constant
// 25 degC and the board cannot protect the coil from heat (the host's heat estimate still
// derates). Every change of the target is logged (GadgetLog).
#pragma once

#include <cstdint>
#include <string>

#include "board/BoardFirmware.hpp"
#include "board/gadget/GadgetLog.hpp"

namespace kf::board::gadget {

struct CoilPins {
  std::string pwmDir;            // e.g. /sys/class/pwm/pwmchip0/pwm0 (exported); "": none
  uint64_t pwmPeriodNs = 50000;  // 20 kHz (PROTOCOL.md 7.4: 20 kHz or more)
  std::string temperatureFile;   // millidegrees C; "": no sensor
};

class GadgetCoil : public CoilDriver {
 public:
  static constexpr double kNoSensorC = 25.0;

  GadgetCoil(GadgetLog& log, CoilPins pins);
  ~GadgetCoil() override;  // the PWM pin off
  // Sets the PWM period, duty 0 and enables it; false with the reason.
  bool open(std::string& error);

  void setTarget(uint16_t drive, double timeS, const char* why) override;
  double temperatureC(double nowS) override;
  uint16_t target() const { return target_; }

 private:
  GadgetLog& log_;
  const CoilPins pins_;
  int dutyFd_ = -1;
  int temperatureFd_ = -1;
  uint16_t target_ = 0;
  double temperatureC_ = kNoSensorC;
  double temperatureReadS_ = -1.0;
};

}  // namespace kf::board::gadget
