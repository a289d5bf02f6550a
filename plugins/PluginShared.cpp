#include "PluginShared.hpp"

#include <atomic>
#include <cstdarg>
#include <cstdint>
#include <cstdio>

#include "DeviceSlots.hpp"
#include "ExitSafety.hpp"
#include "SlotDrive.hpp"

InterfaceTable* ft = nullptr;

namespace kf::sc {

namespace {

// A ring of message slots in static storage: formatting needs no allocation. A slot is busy
// from its formatting until the NRT thread has printed it; a message finding its slot still
// busy (more than kSlots messages in flight) is dropped rather than written over a slot that
// is being printed.
constexpr int kSlots = 64;
constexpr int kSlotChars = 256;
char gSlots[kSlots][kSlotChars];
std::atomic<bool> gSlotBusy[kSlots];
std::atomic<unsigned> gNextSlot{0};

void printSlot(FifoMsg* msg) {
  const int index = static_cast<int>(reinterpret_cast<intptr_t>(msg->mData));
  Print("%s", gSlots[index]);
  gSlotBusy[index].store(false, std::memory_order_release);
}

}  // namespace

void postFromRt(World* world, const char* format, ...) {
  const int index = static_cast<int>(gNextSlot.fetch_add(1, std::memory_order_relaxed) % kSlots);
  if (gSlotBusy[index].exchange(true, std::memory_order_acquire)) return;
  char* slot = gSlots[index];
  va_list args;
  va_start(args, format);
  std::vsnprintf(slot, kSlotChars, format, args);
  va_end(args);
  if (!world->mRealTime) {
    Print("%s", slot);
    gSlotBusy[index].store(false, std::memory_order_release);
    return;
  }
  FifoMsg msg;
  msg.Set(world, printSlot, nullptr, reinterpret_cast<void*>(static_cast<intptr_t>(index)));
  if (!SendMsgFromRT(world, msg)) gSlotBusy[index].store(false, std::memory_order_release);
}

}  // namespace kf::sc

// scsynth's /quit (World_Cleanup) calls each plugin's `unload` before it stops the audio driver and
// frees the nodes. Waiting for FrictionOut's destructors would wait for the driver's stop too
// (JACK's deactivation): the off came 2.005 ms after the last force frame once, past the 2 ms an
// orderly stop must meet (test_orderly_off). So the magnet and the audio drives go off here.
C_LINKAGE SC_API_EXPORT void unload() {
  kf::sc::haltRealtimeDevicesOnQuit();
  kf::sc::haltAllDrives();
}

PluginLoad(KineticFriction) {
  ft = inTable;
  registerSpatialBufRd();
  registerSpatialBufRd2D();
  registerSpeedGovernor();
  registerLoudnessToFriction();
  registerFrictionPattern();
  registerFrictionMouseIn();
  registerFrictionButtons();
  registerFrictionOut();
  registerFrictionDrive();
  registerDeviceCommands();
  registerBoardCommands();
  registerMouseCommands();
  registerDriveCommands();
  installExitSafety();
}
