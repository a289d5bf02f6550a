// Device slots by index, shared by all UGens of a server. The NRT thread opens and closes
// devices (asynchronous commands); the audio thread sees a slot's device through an atomic
// pointer it loads once per block, and never keeps it across blocks.
//
// Reports are fanned out on the audio side: the first FrictionMouseIn of a block that asks a
// slot pops its queue (single consumer) into the slot's SlotTrajectory, whose position
// entries every FrictionMouseIn of that block then reads: one position per device. Forces
// are fanned in the same way: every FrictionOut of a slot adds into its SlotForce, which sends
// the device one frame per millisecond.
#pragma once

#include <atomic>
#include <cstdint>

#include "SlotForce.hpp"
#include "SlotTrajectory.hpp"
#include "core/Device.hpp"

namespace kf::sc {

constexpr int kNumDeviceSlots = 16;
constexpr int kMaxReportsPerBlock = 256;

struct SlotView {
  Device* device = nullptr;                    // null: closed or never opened
  uint32_t generation = 0;                     // changes whenever the slot's device does
  const SlotTrajectory* trajectory = nullptr;  // this block's position entries, references
};

// Audio thread. Out-of-range indices give an empty view. A lockstep device is pumped to the
// end of the block before its reports are taken.
SlotView viewSlot(int index, const BlockClock& clock);

// Audio thread (RT stage of kfZero): from the next block on, the slot's latest reported
// position reads (xMm, yMm). False when no device is open there.
bool requestSlotPosition(int index, double xMm, double yMm);

// Audio thread: the slot's force combiner (one per slot, whether a device is open or not);
// null for an out-of-range index.
SlotForce* forceOfSlot(int index);

// Audio thread: the slot's device, pumped to lockstepTimeS if it runs in lockstep.
Device* deviceOfSlot(int index, double lockstepTimeS, uint32_t* generation);

// RT stage of the commands: publishes `device` (may be null) in the slot and returns the
// previous one, for the NRT stage to close and delete with deleteRetired. Until then the
// previous device is "retired": should the server exit first (a close followed at once by
// /quit), the exit hook closes it, so its magnet goes off.
Device* exchangeSlot(int index, Device* device);

// NRT stage: deletes a device exchangeSlot returned, unless the exit hook already has.
void deleteRetired(Device* device);

// Any thread: the device for a status query (NRT stages only: the device stays alive because
// it is only ever deleted in a later NRT stage).
Device* peekSlot(int index);

bool isValidSlot(int index);

// Any thread: the generation of the slot's device (0 for an invalid slot).
uint32_t generationOfSlot(int index);

// Any thread: how many devices were closed in the slot (a device replaced by another is not
// closed; 0 for an invalid slot). A force writer that saw a device and then a close stops: the
// next device opened there is not the one it was written for (FrictionOut).
uint32_t closesOfSlot(int index);

// Signal handlers (ExitSafety.cpp): Device::emergencyOff on every device in a slot and every
// retired one (its close has not finished), taking the retired ones so that their NRT stage does
// not delete them meanwhile. Atomic operations only, so async-signal-safe. A device whose NRT
// stage is already deleting it is the one race this last-resort path accepts.
void haltAllDevices();

// The server quitting (/quit: the plugin's unload, which scsynth calls before it stops the audio
// driver and frees the nodes): Device::haltInOrder on every realtime device in a slot, so the
// magnet goes off now and the blocks the audio still runs send it nothing. Lockstep devices (an
// NRT render ending) are left to FrictionOut's destructors, which record the off at render time.
// Not for signal handlers (it takes each device's lock).
void haltRealtimeDevicesOnQuit();

// The slot a UGen's device input names, or -1 for NaN, infinities and anything outside
// 0..kNumDeviceSlots-1 (a cast of those to int would be undefined).
inline int slotIndexOf(float input) {
  return input >= 0.f && input < static_cast<float>(kNumDeviceSlots) ? static_cast<int>(input) : -1;
}

}  // namespace kf::sc
