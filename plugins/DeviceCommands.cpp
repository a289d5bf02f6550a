// Asynchronous plugin commands that open, record, query and close device slots. Each is
// usable from sclang (/cmd) and inside a Score. The RT stage only copies arguments and swaps
// slot pointers; everything that allocates, blocks or does I/O runs in the NRT stages.
//
//   kfOpenSim    index kind numValues values... [key value]...   kind: -1 none, 0 path
//                (timeS, xMm pairs), 1 speeds (speedMmPerS, durationS pairs), 2 force (N)
//   kfOpenReplay index path [key value]...   (also startS, skipIdle 0/1, loop 0/1, rate)
//   kfRecord     index path        (an empty path stops recording)
//   kfStatus     index             (posts telemetry)
//   kfClose      index
//   kfZero       index [xMm yMm]   (the puck's latest reported position becomes (x, y), 0 by
//                                   default, for every reader, from the next block on)
//
// Replies follow the server's conventions (CommandRunner.hpp): `/done cmdName` when a command
// succeeded; when it failed, no /done but `/kfFail` to the notified clients, and the reason is
// posted. The open commands refuse a slot that holds a device unless given the setting
// `replace 1`. `/sync` works after all. Real mice: MouseCommands.cpp; the board: BoardCommands.cpp.
#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "AudioClock.hpp"
#include "BoardStatus.hpp"
#include "CommandRunner.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"
#include "core/DeviceMessages.hpp"

namespace {

using namespace kf::sc;

kf::HandScript handScriptOf(const CommandData* data) {
  const CommandArgs& args = data->args;
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

// --- kfOpenSim -----------------------------------------------------------------------------

bool openSimStage(World* world, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  kf::DeviceSpec spec;
  kf::SimParams sim;
  if (!applyOverrides(data, spec, &sim)) return false;
  const kf::HandScript hand = handScriptOf(data);
  if (data->args.kind >= 0 && !hand.isValid()) {
    failWith(data,
             "kfOpenSim: the hand script is not usable (times must ascend; times, positions and durations within "
             "+-1e6 s/mm, speeds within +-1e5 mm/s, a force within +-100 N); not opened");
    return false;
  }
  std::string error;
  data->ownsDevice = true;
  data->device = kf::openSimDevice(spec, sim, hand, !world->mRealTime, &error).release();
  if (data->device == nullptr) failWith(data, "kfOpenSim: %s", error.c_str());
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
  kf::ReplayOptions replay;
  if (!applyOverrides(data, spec, nullptr, &replay)) return false;
  std::string error, warning;
  data->ownsDevice = true;
  data->device = kf::openReplayDevice(data->args.path, spec, !world->mRealTime, error, {}, &warning, replay).release();
  if (data->device == nullptr) failWith(data, "kfOpenReplay: %s", error.c_str());
  if (!warning.empty()) Print("kfOpenReplay: warning: %s\n", warning.c_str());
  return data->device != nullptr;
}

void openReplayCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfOpenReplay", CommandShape::kOpenReplay, args);
  if (data != nullptr) run(world, replyAddr, data, openReplayStage, publishStage, deletePreviousStage);
}

// --- kfRecord, kfStatus --------------------------------------------------------------------

bool recordStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (data->device == nullptr) {
    failWith(data, "kfRecord: no device is open at index %d", data->args.index);
    return false;
  }
  if (data->args.path[0] == '\0') {
    data->device->stopRecording();
    return true;
  }
  std::string error;
  if (!data->device->startRecording(data->args.path, error)) {
    failWith(data, "kfRecord: %s", error.c_str());
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
  const uint64_t pumps = t.framesPerPump[0] + t.framesPerPump[1] + t.framesPerPump[2] + t.framesPerPump[3];
  if (pumps > 0)
    Print(
        "kfStatus %d: frames per 1 ms pump 0/1/2/3+: %.3f/%.3f/%.3f/%.3f, from due time p50 %.3f ms p99 %.3f ms max "
        "%.3f ms, release latency %.2f ms, late %llu\n",
        data->args.index, t.framesPerPump[0] / double(pumps), t.framesPerPump[1] / double(pumps),
        t.framesPerPump[2] / double(pumps), t.framesPerPump[3] / double(pumps), t.frameOffset.p50S * 1e3,
        t.frameOffset.p99S * 1e3, t.frameOffset.maxS * 1e3, t.releaseLatencyS * 1e3,
        static_cast<unsigned long long>(t.lateFrames));
  kf::sc::postBoardStatus(data->args.index, *data->device);
  const std::string source = data->device->mouseBackend().statusLine();
  if (!source.empty()) Print("kfStatus %d: %s\n", data->args.index, source.c_str());
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

// --- kfZero --------------------------------------------------------------------------------

bool rtNothing(World*, void*) { return true; }

void zeroCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfZero", CommandShape::kPosition, args);
  if (data == nullptr) return;
  // At once, in the RT thread at the command's time (a bundle's time stamp): every reader of
  // the slot is re-based at the next block. The asynchronous part only answers /done.
  if (!kf::sc::requestSlotPosition(data->args.index, data->args.positionMm[0], data->args.positionMm[1])) {
    failWith(data, "kfZero: no device is open at index %d", data->args.index);
    kf::sc::postFromRt(world, "%s\n", data->reason);
    replyFailure(world, data);
    return freeCommand(world, data);
  }
  run(world, replyAddr, data, nrtHop, rtNothing, nrtHop);
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
  DefinePlugInCmd("kfZero", zeroCmd, nullptr);
}
