// QemuInput: moves QEMU's emulated USB mouse from inside the guest, through the host hook and
// QMP input-send-event (QEMU's own input layer, as a host's mouse would move it): the USB mouse
// queues the events and answers the guest's xHCI interrupt transfers with boot-protocol reports
// (3 buttons, X, Y, wheel: 8 bits each; a larger move is split over several reports).
// The events go to the USB mouse the guest polled last (QEMU activates a mouse's input handler
// at its first poll): with one plugged in, that one.
#pragma once

#include <string>

namespace kf::guest {

// One relative move (both axes in one event batch: one report when the guest takes it at once).
void qemuMove(int dx, int dy);
// "left", "right", "middle" (buttons 1, 2, 3), "wheel-up", "wheel-down".
void qemuButton(const std::string& button, bool down);

}  // namespace kf::guest
