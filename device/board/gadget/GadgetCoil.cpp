#include "board/gadget/GadgetCoil.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace kf::board::gadget {

namespace {

constexpr double kSensorPeriodS = 0.1;  // a temperature moves in seconds: read it ten times a second

bool writeAttribute(const std::string& path, const std::string& text, std::string& error) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  const bool written = fd >= 0 && ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  if (!written) error = "cannot write '" + text + "' to " + path + ": " + std::strerror(errno);
  if (fd >= 0) ::close(fd);
  return written;
}

}  // namespace

GadgetCoil::GadgetCoil(GadgetLog& log, CoilPins pins) : log_(log), pins_(std::move(pins)) {}

GadgetCoil::~GadgetCoil() {
  if (dutyFd_ >= 0) {
    ::pwrite(dutyFd_, "0\n", 2, 0);
    ::close(dutyFd_);
    std::string ignored;
    writeAttribute(pins_.pwmDir + "/enable", "0\n", ignored);
  }
  if (temperatureFd_ >= 0) ::close(temperatureFd_);
}

bool GadgetCoil::open(std::string& error) {
  if (!pins_.temperatureFile.empty()) {
    temperatureFd_ = ::open(pins_.temperatureFile.c_str(), O_RDONLY | O_CLOEXEC);
    if (temperatureFd_ < 0) {
      error = "cannot open the temperature sensor " + pins_.temperatureFile + ": " + std::strerror(errno);
      return false;
    }
  }
  if (pins_.pwmDir.empty()) return true;
  // The duty first: a period shorter than the duty left from before is refused.
  if (!writeAttribute(pins_.pwmDir + "/duty_cycle", "0\n", error) ||
      !writeAttribute(pins_.pwmDir + "/period", std::to_string(pins_.pwmPeriodNs) + "\n", error) ||
      !writeAttribute(pins_.pwmDir + "/enable", "1\n", error))
    return false;
  dutyFd_ = ::open((pins_.pwmDir + "/duty_cycle").c_str(), O_WRONLY | O_CLOEXEC);
  if (dutyFd_ < 0) {
    error = "cannot open " + pins_.pwmDir + "/duty_cycle: " + std::strerror(errno);
    return false;
  }
  return true;
}

void GadgetCoil::setTarget(uint16_t drive, double, const char* why) {
  target_ = drive;
  if (dutyFd_ >= 0) {
    // sysfs takes the whole value in one write at offset 0.
    char text[32];
    const int size = std::snprintf(text, sizeof text, "%llu\n",
                                   static_cast<unsigned long long>(pins_.pwmPeriodNs * drive / kDriveFull));
    if (::pwrite(dutyFd_, text, static_cast<size_t>(size), 0) != size)
      std::fprintf(stderr, "kf_board_gadget: cannot set the PWM duty: %s\n", std::strerror(errno));
  }
  // Logged when the pin changed, not at the firmware's moment for it (the watchdog's is its exact
  // 20 ms): what the coil saw, late by however long the tick that noticed it was.
  log_.target(monotonicNs(), drive, why);
}

double GadgetCoil::temperatureC(double nowS) {
  if (temperatureFd_ < 0 || (temperatureReadS_ >= 0.0 && nowS - temperatureReadS_ < kSensorPeriodS))
    return temperatureC_;
  temperatureReadS_ = nowS;
  char text[32] = {};
  const ssize_t size = ::pread(temperatureFd_, text, sizeof text - 1, 0);
  char* end = nullptr;
  const double milliC = size > 0 ? std::strtod(text, &end) : NAN;
  // A sensor that cannot be read is too hot: the coil stays off until it reads again.
  temperatureC_ = (size > 0 && end != text && std::isfinite(milliC)) ? milliC / 1000.0 : 1000.0;
  return temperatureC_;
}

}  // namespace kf::board::gadget
