// What every UGen file of the plugin shares: the interface table and RT-safe posting.
#pragma once

#include <SC_PlugIn.hpp>

#include <cmath>
#include <cstdint>

#include "core/PrintfFormat.hpp"
extern InterfaceTable* ft;

namespace kf::sc {

// A value for a message: NaN without the sign printf would show ("-nan").
inline double shownValue(double value) { return std::isnan(value) ? std::fabs(value) : value; }

// An input read as an integer code (an interpolation mode): NaN, inf and values beyond int give
// -1, which is no code (the UGen's default mode), where a cast would be undefined.
inline int codeOf(float input) { return input > -1e9f && input < 1e9f ? static_cast<int>(input) : -1; }

// Posts a message without doing I/O on the audio thread: the text is formatted into static
// storage and printed by the NRT thread (directly when rendering a Score, where there is no
// realtime audio thread to protect).
void postFromRt(World* world, const char* format, ...) KF_PRINTF_FORMAT(2, 3);

// Each kind of bad input of one unit is posted once, the first time it happens: a bad value
// held for an hour posts one line, not one a block, and so does an input that flips between good
// and bad every block (a kind is never re-armed: a storm of lines is the harm this prevents).
// The UGen numbers its kinds 0..31.
class FirstTimeOnly {
 public:
  bool first(int kind) {
    const uint32_t bit = uint32_t{1} << kind;
    const bool isFirst = (posted_ & bit) == 0;
    posted_ |= bit;
    return isFirst;
  }

 private:
  uint32_t posted_ = 0;
};

// Which device a device UGen follows: one warning while its slot is closed (again after a device
// came and went), one for a device input that is no slot number (once per unit, as every bad
// input), and word of a device it has not seen yet, so that it resets its state.
class SlotFollower {
 public:
  void closed(World* world, const char* ugenName, int index, const char* consequence) {
    generation_ = 0;
    if (warned_) return;
    warned_ = true;
    postFromRt(world, "%s: no device is open at index %d; %s\n", ugenName, index, consequence);
  }
  // The device input is no slot number (NaN, inf, negative, 16 or more).
  void badIndex(World* world, const char* ugenName, float input, int numSlots, const char* consequence) {
    generation_ = 0;
    if (!badIndex_.first(0)) return;
    postFromRt(world, "%s: device %g is not a slot number 0..%d; %s\n", ugenName, shownValue(input), numSlots - 1,
               consequence);
  }
  // True when the slot's device (by generation) is not the one followed so far.
  bool isNew(uint32_t generation) {
    warned_ = false;
    if (generation == generation_) return false;
    generation_ = generation;
    return true;
  }

 private:
  uint32_t generation_ = 0;
  bool warned_ = false;
  FirstTimeOnly badIndex_;
};

}  // namespace kf::sc

// Registration hooks, one per UGen file, called from PluginLoad.
void registerSpatialBufRd();
void registerSpatialBufRd2D();
void registerSpeedGovernor();
void registerLoudnessToFriction();
void registerFrictionPattern();
void registerFrictionMouseIn();
void registerFrictionButtons();
void registerFrictionOut();
void registerFrictionDrive();
void registerDeviceCommands();
void registerBoardCommands();
void registerMouseCommands();
void registerDriveCommands();
