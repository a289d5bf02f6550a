// The fix named when a mouse's node may not be opened (hidraw or evdev, Linux): the udev rule.
#include "mouse/MouseIo.hpp"

namespace kf {

std::string permissionFix(const std::string& path) {
  return "permission denied opening " + path +
         ". Fix: install KineticFriction's udev rule (device/mouse/udev/ of the repository, udev/ of the "
         "extension folder): sudo cp 70-kineticfriction.rules /etc/udev/rules.d/ && sudo udevadm control "
         "--reload && sudo udevadm trigger, then unplug and replug the mouse";
}

}  // namespace kf
