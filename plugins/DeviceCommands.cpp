// Asynchronous plugin commands that open, record, query and close device slots. Each is
// usable from sclang (/cmd) and inside a Score. The RT stage only copies arguments and swaps
// slot pointers; everything that allocates, blocks or does I/O runs in the NRT stages.
//
//   kfOpenSim    index kind numValues values... [key value]...   kind: -1 none, 0 path
//                (timeS, xMm pairs), 1 speeds (speedMmPerS, durationS pairs), 2 force (N)
//   kfOpenReplay index path [key value]...
//   kfRecord     index path        (an empty path stops recording)
//   kfStatus     index             (posts telemetry)
//   kfClose      index
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "AudioClock.hpp"
#include "DeviceFactory.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"

namespace {

constexpr int kMaxValues = 8192;
constexpr int kMaxOverrides = 32;
constexpr int kMaxKeyChars = 48;
constexpr int kMaxPathChars = 1024;

struct CommandData {
  const char* name;
  int index;
  int kind;
  int numValues;
  int numOverrides;
  char keys[kMaxOverrides][kMaxKeyChars];
  double overrideValues[kMaxOverrides];
  char path[kMaxPathChars];
  kf::Device* device;    // opened by stage 2, or the target of record/status
  kf::Device* previous;  // swapped out of the slot, deleted in an NRT stage
  double* values;        // the hand script (kfOpenSim only), RTAlloc'd to its size
};

void copyString(char* to, const char* from, size_t capacity) {
  std::snprintf(to, capacity, "%s", from != nullptr ? from : "");
}

CommandData* newCommand(World* world, const char* name, sc_msg_iter* args) {
  auto* data = static_cast<CommandData*>(RTAlloc(world, sizeof(CommandData)));
  if (data == nullptr) {
    kf::sc::postFromRt(world, "%s: RT memory allocation failed\n", name);
    return nullptr;
  }
  data->name = name;
  data->index = args->geti(-1);
  data->kind = -1;
  data->numValues = data->numOverrides = 0;
  data->path[0] = '\0';
  data->device = data->previous = nullptr;
  data->values = nullptr;
  return data;
}

// Trailing (key, value) pairs: device spec or simulation settings by name.
void readOverrides(sc_msg_iter* args, CommandData* data) {
  while (args->remain() > 0 && data->numOverrides < kMaxOverrides) {
    const char* key = args->gets(nullptr);
    if (key == nullptr) break;
    copyString(data->keys[data->numOverrides], key, kMaxKeyChars);
    data->overrideValues[data->numOverrides++] = args->getd(0.0);
  }
}

bool checkSlot(World* world, CommandData* data) {
  if (kf::sc::isValidSlot(data->index)) return true;
  kf::sc::postFromRt(world, "%s: device index %d is out of range 0..%d\n", data->name, data->index,
                     kf::sc::kNumDeviceSlots - 1);
  return false;
}

void freeCommand(World* world, void* raw) {
  auto* data = static_cast<CommandData*>(raw);
  if (data->values != nullptr) RTFree(world, data->values);
  RTFree(world, data);
}

void run(World* world, void* replyAddr, CommandData* data, AsyncStageFn stage2, AsyncStageFn stage3,
         AsyncStageFn stage4) {
  DoAsynchronousCommand(world, replyAddr, data->name, data, stage2, stage3, stage4, freeCommand, 0, nullptr);
}

// Applies the overrides to a spec and simulation settings; false (and a message) on a bad key.
bool applyOverrides(const CommandData* data, kf::DeviceSpec& spec, kf::SimParams* sim) {
  for (int i = 0; i < data->numOverrides; ++i) {
    const char* key = data->keys[i];
    const double value = data->overrideValues[i];
    if (spec.applyOverride(key, value)) continue;
    if (sim != nullptr && sim->applyOverride(key, value)) continue;
    Print("%s: unknown setting or value out of range: %s = %g\n", data->name, key, value);
    return false;
  }
  if (!spec.isValid()) {
    Print("%s: the device settings do not fit together (check force range and rates)\n", data->name);
    return false;
  }
  return true;
}

kf::HandScript handScriptOf(const CommandData* data) {
  std::vector<std::pair<double, double>> pairs;
  for (int i = 0; i + 1 < data->numValues; i += 2) pairs.emplace_back(data->values[i], data->values[i + 1]);
  switch (data->kind) {
    case 0:
      return kf::HandScript::path(std::move(pairs));
    case 1:
      return kf::HandScript::speeds(std::move(pairs));
    case 2:
      return kf::HandScript::constantForce(data->numValues > 0 ? data->values[0] : 0.0);
    default:
      return kf::HandScript::none();
  }
}

// --- stages shared by the open commands ----------------------------------------------------

bool publishStage(World* world, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  // A lockstep device's time starts with the next block, as a realtime one's starts at open.
  if (data->device != nullptr && data->device->isLockstep())
    data->device->setLockstepOriginS(kf::sc::blockStartTimeS(world));
  data->previous = kf::sc::exchangeSlot(data->index, data->device);
  return true;
}

bool deletePreviousStage(World*, void* raw) {  // NRT
  delete static_cast<CommandData*>(raw)->previous;
  return true;
}

// --- kfOpenSim -----------------------------------------------------------------------------

bool openSimStage(World* world, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  kf::DeviceSpec spec;
  kf::SimParams sim;
  if (!applyOverrides(data, spec, &sim)) return false;
  const kf::HandScript hand = handScriptOf(data);
  if (data->kind >= 0 && !hand.isValid()) {
    Print("kfOpenSim: the hand script is not usable (times must ascend, values be finite)\n");
    return false;
  }
  std::string error;
  data->device = kf::openSimDevice(spec, sim, hand, !world->mRealTime, &error).release();
  if (data->device == nullptr) Print("kfOpenSim: %s\n", error.c_str());
  return data->device != nullptr;
}

void openSimCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfOpenSim", args);
  if (data == nullptr) return;
  data->kind = args->geti(-1);
  const int count = std::min(args->geti(0), kMaxValues);
  if (count > 0) {
    data->values = static_cast<double*>(RTAlloc(world, sizeof(double) * count));
    if (data->values == nullptr) {
      kf::sc::postFromRt(world, "kfOpenSim: RT memory allocation failed for the hand script\n");
      return freeCommand(world, data);
    }
  }
  for (int i = 0; i < count && args->remain() > 0; ++i) data->values[data->numValues++] = args->getd(0.0);
  if (count == kMaxValues) kf::sc::postFromRt(world, "kfOpenSim: hand script limited to %d values\n", kMaxValues);
  readOverrides(args, data);
  if (!checkSlot(world, data)) return freeCommand(world, data);
  run(world, replyAddr, data, openSimStage, publishStage, deletePreviousStage);
}

// --- kfOpenReplay --------------------------------------------------------------------------

bool openReplayStage(World* world, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  kf::DeviceSpec spec;
  if (!applyOverrides(data, spec, nullptr)) return false;
  std::string error;
  data->device = kf::openReplayDevice(data->path, spec, !world->mRealTime, error).release();
  if (data->device == nullptr) Print("kfOpenReplay: %s\n", error.c_str());
  return data->device != nullptr;
}

void openReplayCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfOpenReplay", args);
  if (data == nullptr) return;
  copyString(data->path, args->gets(""), kMaxPathChars);
  readOverrides(args, data);
  if (!checkSlot(world, data)) return freeCommand(world, data);
  run(world, replyAddr, data, openReplayStage, publishStage, deletePreviousStage);
}

// --- kfRecord, kfStatus --------------------------------------------------------------------

// Commands that act on the device a slot holds look it up in an RT stage that follows an NRT
// stage: an open sent just before has published its device by then (stages run in order).
bool nrtHop(World*, void*) { return true; }

bool lookUpDeviceStage(World*, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  data->device = kf::sc::peekSlot(data->index);
  return true;
}

bool unpublishStage(World*, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  data->previous = kf::sc::exchangeSlot(data->index, nullptr);
  return true;
}

bool recordStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (data->device == nullptr) {
    Print("kfRecord: no device is open at index %d\n", data->index);
    return false;
  }
  if (data->path[0] == '\0') {
    data->device->stopRecording();
    return true;
  }
  std::string error;
  if (!data->device->startRecording(data->path, error)) {
    Print("kfRecord: %s\n", error.c_str());
    return false;
  }
  return true;
}

void recordCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfRecord", args);
  if (data == nullptr) return;
  copyString(data->path, args->gets(""), kMaxPathChars);
  if (!checkSlot(world, data)) return freeCommand(world, data);
  run(world, replyAddr, data, nrtHop, lookUpDeviceStage, recordStage);
}

bool statusStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (data->device == nullptr) {
    Print("kfStatus %d: closed\n", data->index);
    return true;
  }
  const kf::TelemetrySnapshot t = data->device->telemetry();
  Print(
      "kfStatus %d: %s, reports %llu (interval %.3f ms, jitter %.3f ms), frames %llu, "
      "last force %.4f N, watchdog trips %llu, queue overflows %llu/%llu\n",
      data->index, data->device->isLockstep() ? "lockstep" : "realtime", static_cast<unsigned long long>(t.reports),
      t.reportIntervalMeanS * 1e3, t.reportIntervalJitterS * 1e3, static_cast<unsigned long long>(t.frames),
      t.lastCommandedForceN, static_cast<unsigned long long>(t.watchdogTrips),
      static_cast<unsigned long long>(t.reportQueueOverflows), static_cast<unsigned long long>(t.frameQueueOverflows));
  auto line = [&](const char* what, const kf::LatencySummary& l) {
    if (l.count > 0)
      Print("kfStatus %d: %s p50 %.3f ms, p99 %.3f ms, max %.3f ms (n %llu)\n", data->index, what, l.p50S * 1e3,
            l.p99S * 1e3, l.maxS * 1e3, static_cast<unsigned long long>(l.count));
  };
  line("loop period", t.pumpPeriod);
  line("report to UGen", t.reportLatency);
  line("force to magnet", t.forceLatency);
  const std::string source = data->device->mouseBackend().statusLine();
  if (!source.empty()) Print("kfStatus %d: %s\n", data->index, source.c_str());
  return true;
}

void statusCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfStatus", args);
  if (data == nullptr) return;
  if (!checkSlot(world, data)) return freeCommand(world, data);
  run(world, replyAddr, data, nrtHop, lookUpDeviceStage, statusStage);
}

// --- kfClose -------------------------------------------------------------------------------

void closeCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfClose", args);
  if (data == nullptr) return;
  if (!checkSlot(world, data)) return freeCommand(world, data);
  // Unpublished in the RT stage, between blocks (no UGen sees it from the next block on), after
  // an NRT hop so that an open sent just before is closed too; deleted in the last NRT stage.
  run(world, replyAddr, data, nrtHop, unpublishStage, deletePreviousStage);
}

}  // namespace

void registerDeviceCommands() {
  DefinePlugInCmd("kfOpenSim", openSimCmd, nullptr);
  DefinePlugInCmd("kfOpenReplay", openReplayCmd, nullptr);
  DefinePlugInCmd("kfRecord", recordCmd, nullptr);
  DefinePlugInCmd("kfStatus", statusCmd, nullptr);
  DefinePlugInCmd("kfClose", closeCmd, nullptr);
}
