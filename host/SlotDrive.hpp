// SlotDrive: a slot's audio drive (FrictionDrive): its chain (AudioDrive, for the device it was
// loaded for) and the drive samples of the current block, computed once per block for the first
// FrictionDrive of the slot that asks. Every other FrictionDrive of the slot in that block gets
// none (outputs 0): a slot has one drive, so two FrictionDrive summed into one channel (a guide
// block run twice) never give more than the safe level. In block b it drives block b-1's combined
// force of the slot's FrictionOut (SlotForce::combinedOf): one block late whatever the node
// order (ARCHITECTURE.md, the audio drive). A block that no writer framed (none left, Cmd-., a
// paused writer) drives 0 at once, as the board goes off at once (Device::requestOff); a gap in
// the blocks (no FrictionDrive ran) starts again from the magnet off, so the slew holds.
// Audio thread, except publish (RT stage of kfDriveCalibrate) and haltAllDrives (signals).
#pragma once

#include <cstdint>

#include "SlotForce.hpp"
#include "core/force/AudioDrive.hpp"

namespace kf {
class Device;
}

namespace kf::sc {

class SlotDrive {
 public:
  static constexpr int kMaxBlockSamples = SlotForce::kMaxBlockSamples;

  SlotDrive();

  // Publishes `drive` (null: none) for the device of `generation`; returns the previous chain
  // for an NRT stage to delete. A chain for the same device (a reload) goes on from the
  // previous one's heat and slew, in the same run of blocks; for another device it starts
  // from the magnet off.
  AudioDrive* publish(AudioDrive* drive, uint32_t generation);
  bool hasDrive() const { return drive_ != nullptr; }

  // This block's drive samples (clock.numSamples of them, at most kMaxBlockSamples) for the
  // first caller of the block, or null: no chain, a chain loaded for another device than
  // `generation`, the drives halted, or (`another` true) another caller had this block's drive.
  const float* samples(const BlockClock& clock, uint32_t generation, const SlotForce& force, bool& another);

 private:
  AudioDrive* drive_ = nullptr;
  uint32_t generation_ = 0;
  int64_t computedBlock_ = -1;
  float samples_[kMaxBlockSamples] = {};
};

// Audio thread: the slot's drive, null for an invalid index.
SlotDrive* driveOfSlot(int index);

// RT stage of kfDriveCalibrate: publishes `drive` in slot `index` if the slot still holds the
// device the NRT stage built it for, `generation` and `device` as that stage read them (in that
// order), and hands back the chain it replaced in `drive`. False when the slot's device changed
// meanwhile (closed, replaced, even by a new device at the same address): `drive` is untouched.
bool publishDriveIfSameDevice(int index, uint32_t generation, const Device* device, AudioDrive*& drive);

// Signal handlers (ExitSafety): every drive outputs 0 from the next block on, for good (the
// process is on its way out; should a host's handler keep it alive, the drives stay at 0).
// One atomic store: async-signal-safe.
void haltAllDrives();
// Whether haltAllDrives was called: a FrictionDrive then outputs 0 without a word (its device has
// its calibration; the server is quitting).
bool drivesHalted();

}  // namespace kf::sc
