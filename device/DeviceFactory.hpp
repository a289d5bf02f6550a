// DeviceFactory: opens the kinds of device a slot can hold — simulated or replayed — ready
// to use (realtime: the device thread already runs). Call from a non-realtime thread.
#pragma once

#include <memory>
#include <string>

#include "core/Device.hpp"
#include "core/spec/DeviceSpec.hpp"
#include "recordings/ReplayBackend.hpp"
#include "sim/HandScript.hpp"
#include "sim/SimParams.hpp"

namespace kf {

// A SimDevice as both backends. Null (with a message in *error if given) when the spec or
// hand script is unusable.
std::unique_ptr<Device> openSimDevice(const DeviceSpec& spec, const SimParams& simParams, const HandScript& handScript,
                                      bool lockstep, std::string* error = nullptr, DeviceOptions options = {});

// A ReplayBackend of a kf-session or hid-recorder file, with a CountingForceSink as the force
// side. For kf-session files the spec of the file's header wins over `spec`. `warning`
// receives what was loaded despite a problem (a last line cut mid-way); `replay` where to start,
// whether to loop and at what rate.
std::unique_ptr<Device> openReplayDevice(const std::string& path, const DeviceSpec& spec, bool lockstep,
                                         std::string& error, DeviceOptions options = {}, std::string* warning = nullptr,
                                         const ReplayOptions& replay = {});

}  // namespace kf
