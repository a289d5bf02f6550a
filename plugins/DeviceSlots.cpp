#include "DeviceSlots.hpp"

namespace kf::sc {

namespace {

struct Slot {
  std::atomic<Device*> device{nullptr};
  std::atomic<uint32_t> generation{0};
  // Audio thread only: this block's reports, popped once per block.
  int64_t reportsBlock = -1;
  int numReports = 0;
  MouseReport reports[kMaxReportsPerBlock];
};

Slot gSlots[kNumDeviceSlots];
// One counter for all slots, so that a generation names one device wherever it is: a UGen
// moved to another slot sees a new generation even if both slots were opened equally often.
std::atomic<uint32_t> gNextGeneration{1};

// Closes every device left open when scsynth exits, so no magnet stays on: joins the device
// threads and drives the magnets off.
struct CloseAllAtExit {
  ~CloseAllAtExit() {
    for (Slot& slot : gSlots) delete slot.device.exchange(nullptr);
  }
} gCloseAllAtExit;

}  // namespace

bool isValidSlot(int index) { return index >= 0 && index < kNumDeviceSlots; }

Device* deviceOfSlot(int index, double lockstepTimeS, uint32_t* generation) {
  if (!isValidSlot(index)) return nullptr;
  Slot& slot = gSlots[index];
  Device* device = slot.device.load(std::memory_order_acquire);
  if (generation != nullptr) *generation = slot.generation.load(std::memory_order_acquire);
  if (device != nullptr && device->isLockstep()) device->pump(lockstepTimeS);
  return device;
}

SlotView viewSlot(int index, int64_t blockCounter, double lockstepTimeS) {
  SlotView view;
  view.device = deviceOfSlot(index, lockstepTimeS, &view.generation);
  if (view.device == nullptr) return view;
  Slot& slot = gSlots[index];
  if (slot.reportsBlock != blockCounter) {
    slot.reportsBlock = blockCounter;
    slot.numReports = view.device->popReports(slot.reports, kMaxReportsPerBlock);
  }
  view.reports = slot.reports;
  view.numReports = slot.numReports;
  return view;
}

Device* exchangeSlot(int index, Device* device) {
  if (!isValidSlot(index)) return device;
  Slot& slot = gSlots[index];
  slot.generation.store(gNextGeneration.fetch_add(1, std::memory_order_relaxed), std::memory_order_release);
  slot.reportsBlock = -1;
  slot.numReports = 0;
  return slot.device.exchange(device, std::memory_order_acq_rel);
}

Device* peekSlot(int index) {
  return isValidSlot(index) ? gSlots[index].device.load(std::memory_order_acquire) : nullptr;
}

}  // namespace kf::sc
