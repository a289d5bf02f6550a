// MouseSelect: which of the enumerated mice a user means, in an order that does not change
// from one enumeration to the next.
#pragma once

#include <string>
#include <vector>

#include "mouse/MouseIo.hpp"

namespace kf {

// The order mice are listed and "first" is taken in: external mice (USB, Bluetooth) before
// built-in ones (a trackpoint or touchpad is never the first while a USB mouse is plugged in),
// then interfaces whose reports carry X and Y before others (a vendor interface that also
// declares a mouse collection), then those that are no keyboard's before a keyboard's with a
// mouse collection, then by bus path (the port), interface and node path.
// Enumeration order (readdir, udev) is not stable; this is.
void orderMice(std::vector<MouseInfo>& mice);

// which: "" or "first" the first mouse (orderMice's order); "N" (digits) the N-th (from 0) of
// that order; a path listed ("/dev/hidraw3", "/dev/input/event5": a node that is not a listed
// mouse, a keyboard's, is refused); "VVVV:PPPP" / "VVVV:PPPP:serial" (hex ids); or
// "VVVV:PPPP@busPath": that device in that port and interface (what reselector gives). False
// with a message that lists what there is.
bool selectMouse(std::vector<MouseInfo> mice, const std::string& which, MouseInfo& out, std::string& error);

// The mouse `previous` after a replug (its node path may change): the one with its ids in its
// port and interface; else, when its port is unknown, or it has a serial and came back elsewhere
// (another port, a Bluetooth reconnection), the one mouse with its ids, serial and interface.
// Never one of several of its make, nor a serial-less one elsewhere: a twin in another port is
// not it. False with a message that lists what there is.
bool findMouseAgain(std::vector<MouseInfo> mice, const MouseInfo& previous, MouseInfo& out, std::string& error);

// The selector of this mouse in this port ("VVVV:PPPP@busPath"; without a known port the ids
// and serial): what a re-open looks for, in words.
std::string reselector(const MouseInfo& info);

// "0: /dev/hidraw3 046d:c077 Logitech USB Optical Mouse (serial ..., interface 0)"
std::string describeMouse(int index, const MouseInfo& info);

}  // namespace kf
