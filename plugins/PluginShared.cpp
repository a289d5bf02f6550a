#include "PluginShared.hpp"

#include <atomic>
#include <cstdarg>
#include <cstdio>

InterfaceTable* ft = nullptr;

namespace kf::sc {

namespace {

// A ring of message slots in static storage: formatting needs no allocation, and a slot is
// only reused after 64 later messages, long after the NRT thread printed it.
constexpr int kSlots = 64;
constexpr int kSlotChars = 256;
char gSlots[kSlots][kSlotChars];
std::atomic<unsigned> gNextSlot{0};

void printSlot(FifoMsg* msg) { Print("%s", static_cast<const char*>(msg->mData)); }

}  // namespace

void postFromRt(World* world, const char* format, ...) {
  char* slot = gSlots[gNextSlot.fetch_add(1, std::memory_order_relaxed) % kSlots];
  va_list args;
  va_start(args, format);
  std::vsnprintf(slot, kSlotChars, format, args);
  va_end(args);
  if (!world->mRealTime) {
    Print("%s", slot);
    return;
  }
  FifoMsg msg;
  msg.Set(world, printSlot, nullptr, slot);
  SendMsgFromRT(world, msg);
}

void clearUnitOnAllocFailure(Unit* unit, const char* ugenName) {
  postFromRt(unit->mWorld,
             "%s: RT memory allocation failed; the UGen outputs silence. "
             "Raise ServerOptions.memSize.\n",
             ugenName);
  unit->mCalcFunc = reinterpret_cast<UnitCalcFunc>(ft->fClearUnitOutputs);
  ft->fClearUnitOutputs(unit, 1);
  unit->mDone = true;
}

}  // namespace kf::sc

PluginLoad(KineticFriction) {
  ft = inTable;
  registerSpatialBufRd();
  registerLoudnessToFriction();
  registerFrictionMouseIn();
  registerFrictionOut();
  registerDeviceCommands();
}
