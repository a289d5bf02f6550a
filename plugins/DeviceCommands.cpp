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
#include "CommandArgs.hpp"
#include "DeviceFactory.hpp"
#include "DeviceMessages.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"
#include "PostLimiter.hpp"

namespace {

using kf::sc::CommandShape;

struct CommandData {
  const char* name;
  kf::sc::CommandArgs args;  // args.values: the hand script (kfOpenSim only), RTAlloc'd to its size
  kf::Device* device;        // opened by stage 2, or the target of record/status
  kf::Device* previous;      // swapped out of the slot, deleted in an NRT stage
};

double* allocValues(void* world, int count) {
  return static_cast<double*>(RTAlloc(static_cast<World*>(world), sizeof(double) * static_cast<size_t>(count)));
}

void freeCommand(World* world, void* raw) {
  auto* data = static_cast<CommandData*>(raw);
  if (data->args.values != nullptr) RTFree(world, data->args.values);
  RTFree(world, data);
}

// The arguments after the command name, bounded by the packet: scsynth's own iterator reads
// strings to their terminator wherever it is.
kf::sc::OscArgReader readerOf(sc_msg_iter* msg) {
  if (msg->tags == nullptr || msg->rdpos > msg->endpos) return kf::sc::OscArgReader(nullptr, nullptr, nullptr, nullptr);
  const char* tagsEnd = static_cast<const char*>(std::memchr(msg->tags, '\0', msg->endpos - msg->tags));
  if (tagsEnd == nullptr || tagsEnd - msg->tags < msg->count)
    return kf::sc::OscArgReader(nullptr, nullptr, nullptr, nullptr);
  return kf::sc::OscArgReader(msg->tags + msg->count, msg->endpos, msg->rdpos, msg->endpos);
}

// Refused commands post one line each, and the same refusal at most once a second (a flood
// of one bad command must not flood the post window; different problems all show).
void postRefusal(World* world, const char* name, const char* error) {
  constexpr int kCauses = 16;
  static kf::sc::PostLimiter limiters[kCauses];
  static uint32_t causes[kCauses] = {};
  uint32_t hash = 2166136261u;  // FNV-1a of command and message: the cause
  for (const char* c : {name, error})
    for (; *c != '\0'; ++c) hash = (hash ^ static_cast<uint8_t>(*c)) * 16777619u;
  int slot = static_cast<int>(hash % kCauses);
  if (causes[slot] != hash) {  // another cause had this slot: start afresh
    causes[slot] = hash;
    limiters[slot] = kf::sc::PostLimiter();
  }
  int suppressed = 0;
  if (!limiters[slot].allow(kf::sc::blockStartTimeS(world), suppressed)) return;
  if (suppressed > 0)
    kf::sc::postFromRt(world, "%s: %s; refused (and %d times more since the last message)\n", name, error, suppressed);
  else
    kf::sc::postFromRt(world, "%s: %s; refused\n", name, error);
}

CommandData* newCommand(World* world, const char* name, CommandShape shape, sc_msg_iter* msg) {
  auto* data = static_cast<CommandData*>(RTAlloc(world, sizeof(CommandData)));
  if (data == nullptr) {
    kf::sc::postFromRt(world, "%s: RT memory allocation failed\n", name);
    return nullptr;
  }
  data->name = name;
  data->device = data->previous = nullptr;
  kf::sc::OscArgReader reader = readerOf(msg);
  char error[200];
  if (!kf::sc::parseCommandArgs(shape, reader, kf::sc::kNumDeviceSlots, data->args, allocValues, world, error,
                                sizeof error)) {
    postRefusal(world, name, error);
    freeCommand(world, data);
    return nullptr;
  }
  return data;
}

void run(World* world, void* replyAddr, CommandData* data, AsyncStageFn stage2, AsyncStageFn stage3,
         AsyncStageFn stage4) {
  DoAsynchronousCommand(world, replyAddr, data->name, data, stage2, stage3, stage4, freeCommand, 0, nullptr);
}

// Applies the overrides to a spec and simulation settings; false (and a message) on a bad key.
bool applyOverrides(const CommandData* data, kf::DeviceSpec& spec, kf::SimParams* sim) {
  for (int i = 0; i < data->args.numOverrides; ++i) {
    const char* key = data->args.keys[i];
    const double value = data->args.overrideValues[i];
    std::string error;
    if (spec.applyOverride(key, value, &error)) continue;
    // Not a device setting: perhaps a simulation one (a device setting out of range stays an error).
    const bool unknown = error.rfind("unknown", 0) == 0;
    if (unknown && sim != nullptr && sim->applyOverride(key, value, &error)) continue;
    Print("%s: %s; not opened\n", data->name, error.c_str());
    return false;
  }
  std::string error;
  if (!spec.isValid(&error)) {
    Print("%s: the device settings do not fit together: %s; not opened\n", data->name, error.c_str());
    return false;
  }
  return true;
}

kf::HandScript handScriptOf(const CommandData* data) {
  const kf::sc::CommandArgs& args = data->args;
  std::vector<std::pair<double, double>> pairs;
  for (int i = 0; i + 1 < args.numValues; i += 2) pairs.emplace_back(args.values[i], args.values[i + 1]);
  switch (args.kind) {
    case 0:
      return kf::HandScript::path(std::move(pairs));
    case 1:
      return kf::HandScript::speeds(std::move(pairs));
    case 2:
      return kf::HandScript::constantForce(args.numValues > 0 ? args.values[0] : 0.0);
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
  data->previous = kf::sc::exchangeSlot(data->args.index, data->device);
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
  if (data->args.kind >= 0 && !hand.isValid()) {
    Print(
        "kfOpenSim: the hand script is not usable (times must ascend; times, positions and durations within "
        "+-1e6 s/mm, speeds within +-1e5 mm/s, a force within +-100 N); not opened\n");
    return false;
  }
  std::string error;
  data->device = kf::openSimDevice(spec, sim, hand, !world->mRealTime, &error).release();
  if (data->device == nullptr) Print("kfOpenSim: %s\n", error.c_str());
  return data->device != nullptr;
}

void openSimCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfOpenSim", CommandShape::kOpenSim, args);
  if (data != nullptr) run(world, replyAddr, data, openSimStage, publishStage, deletePreviousStage);
}

// --- kfOpenReplay --------------------------------------------------------------------------

bool openReplayStage(World* world, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  kf::DeviceSpec spec;
  if (!applyOverrides(data, spec, nullptr)) return false;
  std::string error, warning;
  data->device = kf::openReplayDevice(data->args.path, spec, !world->mRealTime, error, {}, &warning).release();
  if (data->device == nullptr) Print("kfOpenReplay: %s\n", error.c_str());
  if (!warning.empty()) Print("kfOpenReplay: warning: %s\n", warning.c_str());
  return data->device != nullptr;
}

void openReplayCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfOpenReplay", CommandShape::kOpenReplay, args);
  if (data != nullptr) run(world, replyAddr, data, openReplayStage, publishStage, deletePreviousStage);
}

// --- kfRecord, kfStatus --------------------------------------------------------------------

// Commands that act on the device a slot holds look it up in an RT stage that follows an NRT
// stage: an open sent just before has published its device by then (stages run in order).
bool nrtHop(World*, void*) { return true; }

bool lookUpDeviceStage(World*, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  data->device = kf::sc::peekSlot(data->args.index);
  return true;
}

bool unpublishStage(World*, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  data->previous = kf::sc::exchangeSlot(data->args.index, nullptr);
  return true;
}

bool recordStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (data->device == nullptr) {
    Print("kfRecord: no device is open at index %d\n", data->args.index);
    return false;
  }
  if (data->args.path[0] == '\0') {
    data->device->stopRecording();
    return true;
  }
  std::string error;
  if (!data->device->startRecording(data->args.path, error)) {
    Print("kfRecord: %s\n", error.c_str());
    return false;
  }
  return true;
}

void recordCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfRecord", CommandShape::kRecord, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, recordStage);
}

bool statusStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (data->device == nullptr) {
    Print("kfStatus %d: closed\n", data->args.index);
    return true;
  }
  const kf::TelemetrySnapshot t = data->device->telemetry();
  Print(
      "kfStatus %d: %s, reports %llu (interval %.3f ms, jitter %.3f ms), frames %llu, "
      "last force %.4f N, watchdog trips %llu, queue overflows %llu/%llu\n",
      data->args.index, data->device->isLockstep() ? "lockstep" : "realtime",
      static_cast<unsigned long long>(t.reports), t.reportIntervalMeanS * 1e3, t.reportIntervalJitterS * 1e3,
      static_cast<unsigned long long>(t.frames), t.lastCommandedForceN,
      static_cast<unsigned long long>(t.watchdogTrips), static_cast<unsigned long long>(t.reportQueueOverflows),
      static_cast<unsigned long long>(t.frameQueueOverflows));
  auto line = [&](const char* what, const kf::LatencySummary& l) {
    if (l.count > 0)
      Print("kfStatus %d: %s p50 %.3f ms, p99 %.3f ms, max %.3f ms (n %llu)\n", data->args.index, what, l.p50S * 1e3,
            l.p99S * 1e3, l.maxS * 1e3, static_cast<unsigned long long>(l.count));
  };
  line("loop period", t.pumpPeriod);
  line("report to UGen", t.reportLatency);
  line("force to magnet", t.forceLatency);
  const std::string recordingError = data->device->recordingError();
  if (!recordingError.empty()) Print("kfStatus %d: recording failed: %s\n", data->args.index, recordingError.c_str());
  return true;
}

void statusCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfStatus", CommandShape::kIndex, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, statusStage);
}

// --- kfClose -------------------------------------------------------------------------------

void closeCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfClose", CommandShape::kIndex, args);
  if (data == nullptr) return;
  // Unpublished in the RT stage, between blocks (no UGen sees it from the next block on), after
  // an NRT hop so that an open sent just before is closed too; deleted in the last NRT stage.
  run(world, replyAddr, data, nrtHop, unpublishStage, deletePreviousStage);
}

}  // namespace

void registerDeviceCommands() {
  // A recording that stops on a write error says so in the post window (device thread).
  kf::setDeviceMessageSink([](const char* message) { Print("%s\n", message); });
  DefinePlugInCmd("kfOpenSim", openSimCmd, nullptr);
  DefinePlugInCmd("kfOpenReplay", openReplayCmd, nullptr);
  DefinePlugInCmd("kfRecord", recordCmd, nullptr);
  DefinePlugInCmd("kfStatus", statusCmd, nullptr);
  DefinePlugInCmd("kfClose", closeCmd, nullptr);
}
