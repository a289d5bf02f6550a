// Asynchronous plugin commands that open, record, query and close device slots. Each is
// usable from sclang (/cmd) and inside a Score. The RT stage only copies arguments and swaps
// slot pointers; everything that allocates, blocks or does I/O runs in the NRT stages.
//
//   kfOpenSim    index kind numValues values... [key value]...   kind: -1 none, 0 path
//                (timeS, xMm pairs), 1 speeds (speedMmPerS, durationS pairs), 2 force (N), 3 path2D
//                (timeS, xMm, yMm triples), 4 line (x0, y0, angleDeg, lengthMm, speed), 5 circle
//                (cx, cy, radiusMm, speed, turns), 6 raster (x0, y0, widthMm, heightMm, rows, speed),
//                7 explore (fromMm, toMm, slowMmPerS, fastMmPerS, tiers, tierS, maxPushN,
//                gainNSPerM, adaptS: a participant, sim/ExploringHand)
//   kfOpenReplay index path [key value]...   (also startS, skipIdle 0/1, loop 0/1, rate)
//   kfRecord     index path        (an empty path stops recording)
//   kfStatus     index [post]      (posts telemetry, unless post is 0, and replies /kfStatus with
//                                   its figures as numbers, to /notify clients: index, then
//                                   kStatusFields values in StatusField order)
//   kfClose      index
//   kfZero       index [xMm yMm]   (the puck's latest reported position becomes (x, y), 0 by
//                                   default, for every reader, from the next block on)
//   kfHeartbeat  index [timeoutS]  (the client is alive; with timeoutS, the device's client watch
//                                   is set: magnet off once no heartbeat came for timeoutS, 0 no
//                                   watch; Device::watchClient)
//   kfSimFail    index             (a simulated realtime device's thread fails, as a driver that
//                                   lost its device would: to rehearse what a study does then)
//   kfSimRelease index             (a simulated device opened with handHeld 1: its hand starts
//                                   its script now, SimDevice::releaseHand)
//
// Replies follow the server's conventions (CommandRunner.hpp): `/done cmdName` when a command
// succeeded; when it failed, no /done but `/kfFail` to the notified clients, and the reason is
// posted. The open commands refuse a slot that holds a device unless given the setting
// `replace 1`. `/sync` works after all. Real mice: MouseCommands.cpp; the board: BoardCommands.cpp.
#include <algorithm>
#include <array>
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
#include "board/UsbBoardBackend.hpp"
#include "core/threads/DeviceMessages.hpp"
#include "sim/SimDevice.hpp"

namespace {

using namespace kf::sc;

// The values of a /kfStatus reply, in order (sclang: FrictionDevice.statusFields). Thread
// priorities: -1 no such thread (or not started), 0 normal scheduling, > 0 SCHED_FIFO.
// Durations in seconds.
enum StatusField {
  kOpen,
  kRealtime,
  kDeviceThreadPriority,
  kMouseThreadPriority,
  kUsbThreadPriority,
  kMemoryLocked,
  kReports,
  kFrames,
  kWatchdogTrips,
  kMissedDeadlines,
  kSkippedFrames,
  kLateFrames,
  kReportQueueOverflows,
  kFrameQueueOverflows,
  kLoopP50S,
  kLoopP99S,
  kLoopMaxS,
  kForceP50S,
  kForceP99S,
  kForceP999S,
  kForceMaxS,
  kReportP50S,
  kReportP99S,
  kReportMaxS,
  kReleaseLatencyS,
  kReportIntervalS,
  kReportJitterS,
  kLastForceN,
  kRecording,      // 1 while a recording is open and has not stopped by itself (a write error)
  kAudioCallMaxS,  // the longest block of a FrictionOut on the audio thread (realtime)
  kFault,          // what of the device failed (DeviceFault): 0 nothing
  kStatusFields
};

static_assert(kStatusFields <= static_cast<int>(sizeof(CommandData::replyValues) / sizeof(float)));

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
    case 3: {
      std::vector<std::array<double, 3>> triples;
      for (int i = 0; i + 2 < args.numValues; i += 3)
        triples.push_back({args.values[i], args.values[i + 1], args.values[i + 2]});
      return kf::HandScript::path2D(std::move(triples));
    }
    case 4:  // the value counts are checked by CommandArgs
      return kf::HandScript::line(args.values[0], args.values[1], args.values[2], args.values[3], args.values[4]);
    case 5:
      return kf::HandScript::circle(args.values[0], args.values[1], args.values[2], args.values[3], args.values[4]);
    case 6:
      return kf::HandScript::raster(args.values[0], args.values[1], args.values[2], args.values[3], args.values[4],
                                    args.values[5]);
    case 7: {
      const double* v = args.values;
      return kf::HandScript::exploring({v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]});
    }
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
  data->device = kf::openSimDevice(spec, sim, hand, !world->mRealTime, &error, deviceOptionsOf(world, data)).release();
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
  data->device = kf::openReplayDevice(data->args.path, spec, !world->mRealTime, error, deviceOptionsOf(world, data),
                                      &warning, replay)
                     .release();
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
  if (!haveDevice(data)) return false;
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

// What of an open device failed, for kFault (sclang: FrictionDevice.faultOf).
enum DeviceFault {
  kNoFault = 0,
  kThreadStopped = 1,      // a backend threw: nothing pumps the device (Device::threadFailed)
  kMouseUnplugged = 2,     // its real mouse is gone (kfReopenMouse when it is back)
  kBoardNotConnected = 3,  // its board is unplugged or not answering
  kBoardFault = 4,         // its board tripped to its fault state (over-current, a power loss)
};

DeviceFault faultOf(kf::Device& device) {
  if (device.threadFailed()) return kThreadStopped;
  if (!device.mouseBackend().connected()) return kMouseUnplugged;
  const std::shared_ptr<kf::ForceBackend> holder = device.board();
  if (const auto* board = dynamic_cast<const kf::UsbBoardBackend*>(holder.get())) {
    const kf::BoardTelemetry t = board->telemetry();
    if (!t.connected) return kBoardNotConnected;
    if (t.haveStatus && t.status.state == kf::board::BoardState::kFault) return kBoardFault;
  }
  return kNoFault;
}

// The figures of the reply (statusStage).
void fillStatusValues(kf::Device& device, const kf::ThreadScheduling& usbThread, float* v) {
  const kf::TelemetrySnapshot t = device.telemetry();
  auto f = [](double value) { return static_cast<float>(value); };
  v[kOpen] = 1.0f;
  v[kRealtime] = device.isLockstep() ? 0.0f : 1.0f;
  v[kDeviceThreadPriority] = f(t.deviceThread.priority);
  v[kMouseThreadPriority] = f(t.mouseThread.priority);
  v[kUsbThreadPriority] = f(usbThread.priority);
  v[kMemoryLocked] = t.deviceThread.memoryLocked ? 1.0f : 0.0f;
  v[kReports] = f(t.reports);
  v[kFrames] = f(t.frames);
  v[kWatchdogTrips] = f(t.watchdogTrips);
  v[kMissedDeadlines] = f(t.missedDeadlines);
  v[kSkippedFrames] = f(t.skippedFrames);
  v[kLateFrames] = f(t.lateFrames);
  v[kReportQueueOverflows] = f(t.reportQueueOverflows);
  v[kFrameQueueOverflows] = f(t.frameQueueOverflows);
  v[kLoopP50S] = f(t.pumpPeriod.p50S);
  v[kLoopP99S] = f(t.pumpPeriod.p99S);
  v[kLoopMaxS] = f(t.pumpPeriod.maxS);
  v[kForceP50S] = f(t.forceLatency.p50S);
  v[kForceP99S] = f(t.forceLatency.p99S);
  v[kForceP999S] = f(t.forceLatency.p999S);
  v[kForceMaxS] = f(t.forceLatency.maxS);
  v[kReportP50S] = f(t.reportLatency.p50S);
  v[kReportP99S] = f(t.reportLatency.p99S);
  v[kReportMaxS] = f(t.reportLatency.maxS);
  v[kReleaseLatencyS] = f(t.releaseLatencyS);
  v[kReportIntervalS] = f(t.reportIntervalMeanS);
  v[kReportJitterS] = f(t.reportIntervalJitterS);
  v[kLastForceN] = t.lastCommandedForceN;
  v[kRecording] = device.isRecording() ? 1.0f : 0.0f;
  v[kAudioCallMaxS] = f(t.audioCallMaxS);
  v[kFault] = static_cast<float>(faultOf(device));
}

// The board's event thread, if the device has a board.
kf::ThreadScheduling usbThreadOf(kf::Device& device) {
  const std::shared_ptr<kf::ForceBackend> holder = device.board();
  const auto* board = dynamic_cast<const kf::UsbBoardBackend*>(holder.get());
  return board != nullptr ? board->threadScheduling() : kf::ThreadScheduling{};
}

bool statusStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  std::fill_n(data->replyValues, static_cast<int>(kStatusFields), 0.0f);
  if (data->device == nullptr) {
    Print("kfStatus %d: closed\n", data->args.index);
    return true;  // replies kOpen 0
  }
  const kf::ThreadScheduling usbThread = usbThreadOf(*data->device);
  fillStatusValues(*data->device, usbThread, data->replyValues);
  if (data->args.numbers[0] == 0.0) return true;  // the figures only: a poller's post window stays readable
  const kf::TelemetrySnapshot t = data->device->telemetry();
  Print(
      "kfStatus %d: %s, reports %llu (interval %.3f ms, jitter %.3f ms), frames %llu, "
      "last force %.4f N, watchdog trips %llu, queue overflows %llu/%llu\n",
      data->args.index, data->device->isLockstep() ? "lockstep" : "realtime",
      static_cast<unsigned long long>(t.reports), t.reportIntervalMeanS * 1e3, t.reportIntervalJitterS * 1e3,
      static_cast<unsigned long long>(t.frames), t.lastCommandedForceN,
      static_cast<unsigned long long>(t.watchdogTrips), static_cast<unsigned long long>(t.reportQueueOverflows),
      static_cast<unsigned long long>(t.frameQueueOverflows));
  if (!data->device->isLockstep()) {
    std::string threads = "device " + kf::describe(t.deviceThread);
    if (t.mouseThread.priority >= 0) threads += "; mouse " + kf::describe(t.mouseThread);
    if (usbThread.priority >= 0) threads += "; usb " + kf::describe(usbThread);
    Print("kfStatus %d: threads: %s; missed deadlines %llu, skipped frames %llu\n", data->args.index, threads.c_str(),
          static_cast<unsigned long long>(t.missedDeadlines), static_cast<unsigned long long>(t.skippedFrames));
  }
  auto line = [&](const char* what, const kf::LatencySummary& l) {
    if (l.count > 0)
      Print("kfStatus %d: %s p50 %.3f ms, p99 %.3f ms, max %.3f ms (n %llu), p99.9 %.3f ms\n", data->args.index, what,
            l.p50S * 1e3, l.p99S * 1e3, l.maxS * 1e3, static_cast<unsigned long long>(l.count), l.p999S * 1e3);
  };
  line("loop period", t.pumpPeriod);
  line("report to UGen", t.reportLatency);
  line("force to magnet", t.forceLatency);
  const std::string recordingError = data->device->recordingError();
  if (!recordingError.empty()) Print("kfStatus %d: recording failed: %s\n", data->args.index, recordingError.c_str());
  static const char* const kFaultTexts[] = {"", "its thread stopped (the post window said why): reopen the device",
                                            "its mouse is unplugged", "its board is not connected",
                                            "its board is in its fault state"};
  if (const auto fault = static_cast<DeviceFault>(data->replyValues[kFault]))
    Print("kfStatus %d: FAILED: %s\n", data->args.index, kFaultTexts[fault]);
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

// RT, at the end: the figures to every client that asked for notifications (sclang's default).
void replyStatus(World* world, CommandData* data) {
  // The plugin headers do not define Group; the server's starts with its Node (SC_Group.h).
  SendNodeReply(reinterpret_cast<Node*>(world->mTopGroup), data->args.index, "/kfStatus", kStatusFields,
                data->replyValues);
}

void statusCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfStatus", CommandShape::kStatus, args);
  if (data == nullptr) return;
  std::fill_n(data->replyValues, static_cast<int>(kStatusFields), 0.0f);
  data->onEnd = replyStatus;
  run(world, replyAddr, data, nrtHop, lookUpDeviceStage, statusStage);
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

// --- kfHeartbeat ---------------------------------------------------------------------------

bool heartbeatStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (!haveDevice(data)) return false;
  if (data->args.numbers[0] >= 0.0)
    data->device->watchClient(data->args.numbers[0]);
  else
    data->device->heartbeat();
  return true;
}

void heartbeatCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfHeartbeat", CommandShape::kHeartbeat, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, heartbeatStage);
}

// --- kfSimFail -----------------------------------------------------------------------------

bool simFailStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (!haveDevice(data)) return false;
  auto* sim = dynamic_cast<kf::SimDevice*>(&data->device->mouseBackend());
  // In lockstep the audio thread pumps the device: an exception there would end the server.
  if (sim == nullptr || data->device->isLockstep()) {
    failWith(data, "kfSimFail: device %d is not a simulated realtime device; refused", data->args.index);
    return false;
  }
  sim->failNextPoll();
  return true;
}

void simFailCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfSimFail", CommandShape::kIndex, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, simFailStage);
}

// --- kfSimRelease --------------------------------------------------------------------------

bool simReleaseStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (!haveDevice(data)) return false;
  auto* sim = dynamic_cast<kf::SimDevice*>(&data->device->mouseBackend());
  if (sim == nullptr || sim->params().handHeld == 0.0) {
    failWith(data, "kfSimRelease: device %d is not a simulated device opened with its hand held (handHeld 1)",
             data->args.index);
    return false;
  }
  sim->releaseHand();
  return true;
}

void simReleaseCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfSimRelease", CommandShape::kIndex, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, simReleaseStage);
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
  DefinePlugInCmd("kfHeartbeat", heartbeatCmd, nullptr);
  DefinePlugInCmd("kfSimFail", simFailCmd, nullptr);
  DefinePlugInCmd("kfSimRelease", simReleaseCmd, nullptr);
}
