#include "MouseDeviceFactory.hpp"

#include <algorithm>

#include "mouse/EvdevMouseBackend.hpp"
#include "mouse/HidapiMouseBackend.hpp"
#include "mouse/MouseSelect.hpp"
#include "recordings/ReplayBackend.hpp"

namespace kf {

bool mouseBackendKindFromName(const std::string& name, MouseBackendKind& out) {
  if (name == "hidapi" || name == "hid") {
    out = MouseBackendKind::kHidapi;
    return true;
  }
  if (name == "evdev") {
    out = MouseBackendKind::kEvdev;
    return true;
  }
  return false;
}

std::unique_ptr<Device> openMouseDevice(const MouseOpenOptions& options, const DeviceSpec& spec, std::string& error,
                                        OpenFailure* why, std::shared_ptr<HidApi> hidApi,
                                        std::shared_ptr<EvdevApi> evdevApi, DeviceOptions deviceOptions) {
  if (!spec.isValid()) {
    error = "invalid device spec";
    if (why) *why = OpenFailure::kOther;
    return nullptr;
  }
  std::shared_ptr<MouseBackend> mouse;
  if (options.kind == MouseBackendKind::kHidapi)
    mouse = HidapiMouseBackend::open(hidApi ? hidApi : realHidApi(), options.which, error, why, deviceOptions.thread);
  else
    mouse = EvdevMouseBackend::open(evdevApi ? evdevApi : realEvdevApi(), options.which, options.grab, error, why,
                                    deviceOptions.thread);
  if (!mouse) return nullptr;
  // A real mouse reports up to 8 kHz: room for 1 s of reports between pumps and the UGen.
  deviceOptions.reportQueueCapacity = std::max<size_t>(deviceOptions.reportQueueCapacity, 8192);
  auto device = std::make_unique<Device>(spec, mouse, std::make_shared<CountingForceSink>(), false, deviceOptions);
  device->start();
  return device;
}

bool listMice(MouseBackendKind kind, std::vector<std::string>& lines, std::string& error,
              std::shared_ptr<HidApi> hidApi, std::shared_ptr<EvdevApi> evdevApi) {
  lines.clear();
  std::vector<MouseInfo> mice;
  const bool ok = kind == MouseBackendKind::kHidapi
                      ? (hidApi ? hidApi : realHidApi())->enumerateMice(mice, error)
                      : (evdevApi ? evdevApi : realEvdevApi())->enumerateMice(mice, error);
  if (!ok) return false;
  for (size_t i = 0; i < mice.size(); ++i) lines.push_back(describeMouse(static_cast<int>(i), mice[i]));
  return true;
}

}  // namespace kf
