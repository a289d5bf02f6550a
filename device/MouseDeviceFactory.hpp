// MouseDeviceFactory: a Device whose position comes from a real mouse (hidapi or evdev) and
// whose force side counts what it is told (no magnet). Realtime only: a real mouse cannot be
// stepped in lockstep with a Score render. Call from a non-realtime thread.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/Device.hpp"
#include "mouse/MouseIo.hpp"

namespace kf {

enum class MouseBackendKind { kHidapi, kEvdev };

// "hidapi" or "evdev" (anything else: false).
bool mouseBackendKindFromName(const std::string& name, MouseBackendKind& out);

// The backend a mouse opens with unless asked: evdev on Linux. It opens every mouse the udev
// rule grants, wireless receivers' among them: the kernel (hid-logitech-dj, hid-generic) gives
// each paired mouse an event node of its own, while its hidraw node sits on the receiver's
// vendor interface with the paired keyboards', which the rule does not grant. hidapi elsewhere.
#ifdef __linux__
constexpr MouseBackendKind kDefaultMouseBackend = MouseBackendKind::kEvdev;
#else
constexpr MouseBackendKind kDefaultMouseBackend = MouseBackendKind::kHidapi;
#endif

struct MouseOpenOptions {
  MouseBackendKind kind = kDefaultMouseBackend;
  std::string which;  // MouseSelect's selector ("" the first mouse)
  bool grab = false;  // evdev: keep the desktop cursor still
};

// Null with a message (naming the node and the fix on permission denied) and why.
std::unique_ptr<Device> openMouseDevice(const MouseOpenOptions& options, const DeviceSpec& spec, std::string& error,
                                        OpenFailure* why = nullptr, std::shared_ptr<HidApi> hidApi = nullptr,
                                        std::shared_ptr<EvdevApi> evdevApi = nullptr, DeviceOptions deviceOptions = {});

// The mice a backend can open, one line each (MouseSelect's describeMouse); false with a
// message when enumeration failed. Finding none is true with no lines.
bool listMice(MouseBackendKind kind, std::vector<std::string>& lines, std::string& error,
              std::shared_ptr<HidApi> hidApi = nullptr, std::shared_ptr<EvdevApi> evdevApi = nullptr);

}  // namespace kf
