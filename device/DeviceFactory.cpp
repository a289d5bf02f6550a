#include "DeviceFactory.hpp"

#include "recordings/ReplayBackend.hpp"
#include "sim/SimDevice.hpp"

namespace kf {

std::unique_ptr<Device> openSimDevice(const DeviceSpec& spec, const SimParams& simParams, const HandScript& handScript,
                                      bool lockstep, std::string* error, DeviceOptions options) {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return std::unique_ptr<Device>();
  };
  std::string why;
  if (!spec.isValid(&why)) return fail("invalid device spec: " + why);
  if (!handScript.isValid())
    return fail("invalid hand script (times must ascend, values within their bounds: see SettingBounds)");
  if (!simParams.isValid(&why)) return fail("invalid sim parameters: " + why);
  auto sim = std::make_shared<SimDevice>(spec, simParams, handScript);
  auto device = std::make_unique<Device>(spec, sim, sim, lockstep, options);
  device->start();
  return device;
}

std::unique_ptr<Device> openReplayDevice(const std::string& path, const DeviceSpec& spec, bool lockstep,
                                         std::string& error, DeviceOptions options, std::string* warning,
                                         const ReplayOptions& replay) {
  DeviceSpec replaySpec = spec;
  std::vector<TimedReport> reports;
  if (!loadReplayReports(path, replaySpec, reports, error, nullptr, warning)) return nullptr;
  std::string why;
  if (!replaySpec.isValid(&why)) {
    error = path + ": invalid device spec: " + why;
    return nullptr;
  }
  auto mouse = std::make_shared<ReplayBackend>(std::move(reports), replay, replaySpec.updateRateHz);
  auto force = std::make_shared<CountingForceSink>();
  auto device = std::make_unique<Device>(replaySpec, mouse, force, lockstep, options);
  device->start();
  return device;
}

}  // namespace kf
