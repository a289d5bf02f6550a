#include "DeviceSlots.hpp"

#include <algorithm>

namespace kf::sc {

namespace {

struct Slot {
  std::atomic<Device*> device{nullptr};
  std::atomic<uint32_t> generation{0};
  std::atomic<uint32_t> closes{0};  // devices closed in this slot (kfClose), replaced ones not
  // Audio thread only: the reports popped in a block, and the slot's position.
  MouseReport reports[kMaxReportsPerBlock];
  SlotTrajectory trajectory;
  SlotForce force;
};

Slot gSlots[kNumDeviceSlots];
// One counter for all slots, so that a generation names one device wherever it is: a UGen
// moved to another slot sees a new generation even if both slots were opened equally often.
std::atomic<uint32_t> gNextGeneration{1};

// Devices out of their slot and not deleted yet (see exchangeSlot). Whoever exchanges an entry
// to null owns the device: the NRT stage or the exit hook, never both. With more in flight
// than entries, a device goes untracked (and is only deleted by its NRT stage).
constexpr int kRetiredCapacity = 64;
std::atomic<Device*> gRetired[kRetiredCapacity];
std::atomic<bool> gExiting{false};

void retire(Device* device) {
  if (device == nullptr) return;
  for (std::atomic<Device*>& entry : gRetired) {
    Device* expected = nullptr;
    if (entry.compare_exchange_strong(expected, device, std::memory_order_acq_rel)) return;
  }
}

// Closes every device left open when scsynth exits, so no magnet stays on: joins the device
// threads and drives the magnets off. Also the devices whose close has not finished.
struct CloseAllAtExit {
  ~CloseAllAtExit() {
    gExiting.store(true);
    Device* closed[kNumDeviceSlots] = {};
    for (int i = 0; i < kNumDeviceSlots; ++i) delete (closed[i] = gSlots[i].device.exchange(nullptr));
    // A device both in its slot and retired (an exchange cut short) was deleted above.
    for (std::atomic<Device*>& entry : gRetired)
      if (Device* device = entry.exchange(nullptr);
          std::find(closed, closed + kNumDeviceSlots, device) == closed + kNumDeviceSlots)
        delete device;
  }
} gCloseAllAtExit;

}  // namespace

bool isValidSlot(int index) { return index >= 0 && index < kNumDeviceSlots; }

uint32_t generationOfSlot(int index) {
  return isValidSlot(index) ? gSlots[index].generation.load(std::memory_order_acquire) : 0;
}

uint32_t closesOfSlot(int index) {
  return isValidSlot(index) ? gSlots[index].closes.load(std::memory_order_acquire) : 0;
}

Device* deviceOfSlot(int index, double lockstepTimeS, uint32_t* generation) {
  if (!isValidSlot(index)) return nullptr;
  Slot& slot = gSlots[index];
  Device* device = slot.device.load(std::memory_order_acquire);
  if (generation != nullptr) *generation = slot.generation.load(std::memory_order_acquire);
  if (device != nullptr && device->isLockstep()) device->pump(lockstepTimeS);
  return device;
}

SlotView viewSlot(int index, const BlockClock& clock) {
  SlotView view;
  view.device = deviceOfSlot(index, clock.startS + clock.numSamples * clock.sampleDurS, &view.generation);
  if (view.device == nullptr) return view;
  Slot& slot = gSlots[index];
  if (!slot.trajectory.hasBlock(clock.block)) {
    // Reports that came while no reader read the slot (before its first reader, or while it had
    // none) waited for no one: the status's reader delay counts from a reader on.
    const bool readerWasReading = slot.trajectory.continuesAt(clock.block);
    int numReports = view.device->popReports(slot.reports, kMaxReportsPerBlock, readerWasReading);
    // A backlog larger than the buffer (nobody read for seconds): the newest report stands for
    // the rest; its absolute counts include them.
    if (numReports == kMaxReportsPerBlock)
      while (view.device->popReports(&slot.reports[kMaxReportsPerBlock - 1], 1, readerWasReading) == 1) {
      }
    slot.trajectory.takeBlock(clock, slot.reports, numReports, view.device->isLockstep(),
                              view.device->lockstepOriginS());
  }
  view.trajectory = &slot.trajectory;
  return view;
}

bool requestSlotPosition(int index, double xMm, double yMm) {
  if (!isValidSlot(index) || gSlots[index].device.load(std::memory_order_acquire) == nullptr) return false;
  gSlots[index].trajectory.requestPosition(xMm, yMm);
  return true;
}

Device* exchangeSlot(int index, Device* device) {
  if (!isValidSlot(index)) return device;
  Slot& slot = gSlots[index];
  slot.generation.store(gNextGeneration.fetch_add(1, std::memory_order_relaxed), std::memory_order_release);
  slot.trajectory.reset(device != nullptr ? device->spec() : DeviceSpec{});
  slot.force.reset(device != nullptr ? device->spec() : DeviceSpec{});
  // Retired before it leaves the slot, so a signal handler in between still finds it (only this
  // RT stage writes slots while the server runs).
  Device* previous = slot.device.load(std::memory_order_acquire);
  retire(previous);
  if (device == nullptr && previous != nullptr) slot.closes.fetch_add(1, std::memory_order_acq_rel);
  slot.device.store(device, std::memory_order_release);
  return previous;
}

void deleteRetired(Device* device) {
  if (device == nullptr) return;
  for (std::atomic<Device*>& entry : gRetired) {
    Device* expected = device;
    if (entry.compare_exchange_strong(expected, nullptr, std::memory_order_acq_rel)) {
      delete device;
      return;
    }
  }
  // Not found: taken by the exit hook (which set gExiting before taking any), or never tracked
  // (the table was full), then this stage owns it alone.
  if (!gExiting.load()) delete device;
}

SlotForce* forceOfSlot(int index) { return isValidSlot(index) ? &gSlots[index].force : nullptr; }

Device* peekSlot(int index) {
  return isValidSlot(index) ? gSlots[index].device.load(std::memory_order_acquire) : nullptr;
}

void haltRealtimeDevicesOnQuit() {
  for (Slot& slot : gSlots) {
    Device* device = slot.device.load(std::memory_order_acquire);
    if (device != nullptr && !device->isLockstep()) device->haltInOrder();
  }
}

void haltAllDevices() {
  gExiting.store(true);
  for (Slot& slot : gSlots)
    if (Device* device = slot.device.load(std::memory_order_acquire)) device->emergencyOff();
  // Retired devices are taken, so that their NRT stage no longer deletes them while they are
  // being halted (the process is ending: they are never deleted).
  for (std::atomic<Device*>& entry : gRetired)
    if (Device* device = entry.exchange(nullptr, std::memory_order_acq_rel)) device->emergencyOff();
}

}  // namespace kf::sc
