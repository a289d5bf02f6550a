// DescriptorKind: what a hidraw node's report descriptor says about it as a mouse, for the
// order mice are listed in (MouseSelect's orderMice): whether its reports carry relative X and
// Y, and whether it is a keyboard's too (a keyboard with a pointing stick, a gaming mouse's
// macro keys on one interface). Read from sysfs at enumeration, before any open.
#pragma once

#include <cstdint>
#include <vector>

namespace kf {

struct DescriptorKind {
  bool parsed = false;       // false: unreadable or refused; the rest is then unknown
  bool hasXY = false;        // an input field with relative X (0x30) and Y (0x31), Generic Desktop
  bool hasKeyboard = false;  // an application collection Keyboard (1:6) or Keypad (1:7)
};

DescriptorKind descriptorKind(const std::vector<uint8_t>& descriptor);

}  // namespace kf
