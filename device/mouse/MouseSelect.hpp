// MouseSelect: which of the enumerated mice a user means.
#pragma once

#include <string>
#include <vector>

#include "mouse/MouseIo.hpp"

namespace kf {

// which: "" or "first" the first mouse; "N" (digits) the N-th (from 0) of the list; a path
// ("/dev/hidraw3", "/dev/input/event5"); or "VVVV:PPPP" / "VVVV:PPPP:serial" (hex ids). A
// path that is not in the list is still used (hidraw nodes of composite devices). False with
// a message that lists what there is.
bool selectMouse(const std::vector<MouseInfo>& mice, const std::string& which, MouseInfo& out, std::string& error);

// A selector that finds the same mouse again after a replug (its path may change).
std::string reselector(const MouseInfo& info);

// "0: /dev/hidraw3 046d:c077 Logitech USB Optical Mouse (serial ..., interface 0)"
std::string describeMouse(int index, const MouseInfo& info);

}  // namespace kf
