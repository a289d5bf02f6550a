#include "CommandRunner.hpp"

#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "AudioClock.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"
#include "PostLimiter.hpp"
#include "core/spec/SettingBounds.hpp"
#include "core/threads/ThreadScheduling.hpp"

namespace kf::sc {

namespace {

// The same from an NRT stage: a copy of the reason travels to the RT thread.
struct FailureCopy {
  CommandData data;
};

void replyFailureFromNrt(World* world, const CommandData* data) {
  // A non-realtime server (a Score rendering) runs every stage on its one thread, and scsynth's
  // has no audio driver to take a message to the RT side (SendMsgToRT crashed it): reply here.
  if (!world->mRealTime) {
    replyFailure(world, data);
    return;
  }
  auto* copy = static_cast<FailureCopy*>(NRTAlloc(sizeof(FailureCopy)));
  if (copy == nullptr) return;
  std::memcpy(&copy->data, data, sizeof(CommandData));
  FifoMsg msg;
  msg.Set(
      world, [](FifoMsg* m) { replyFailure(m->mWorld, &static_cast<FailureCopy*>(m->mData)->data); },
      [](FifoMsg* m) { NRTFree(m->mData); }, copy);
  SendMsgToRT(world, msg);
}

double* allocValues(void* world, int count) {
  return static_cast<double*>(RTAlloc(static_cast<World*>(world), sizeof(double) * static_cast<size_t>(count)));
}

// The arguments after the command name, bounded by the packet: scsynth's own iterator reads
// strings to their terminator wherever it is.
OscArgReader readerOf(sc_msg_iter* msg) {
  if (msg->tags == nullptr || msg->rdpos > msg->endpos) return OscArgReader(nullptr, nullptr, nullptr, nullptr);
  const char* tagsEnd = static_cast<const char*>(std::memchr(msg->tags, '\0', msg->endpos - msg->tags));
  if (tagsEnd == nullptr || tagsEnd - msg->tags < msg->count) return OscArgReader(nullptr, nullptr, nullptr, nullptr);
  return OscArgReader(msg->tags + msg->count, msg->endpos, msg->rdpos, msg->endpos);
}

// Refused commands post one line each, and the same refusal at most once a second (a flood
// of one bad command must not flood the post window; different problems all show).
void postRefusal(World* world, const char* reason) {
  constexpr int kCauses = 16;
  static PostLimiter limiters[kCauses];
  static uint32_t causes[kCauses] = {};
  uint32_t hash = 2166136261u;  // FNV-1a of the reason (it names the command): the cause
  for (const char* c = reason; *c != '\0'; ++c) hash = (hash ^ static_cast<uint8_t>(*c)) * 16777619u;
  int slot = static_cast<int>(hash % kCauses);
  if (causes[slot] != hash) {  // another cause had this slot: start afresh
    causes[slot] = hash;
    limiters[slot] = PostLimiter();
  }
  int suppressed = 0;
  if (!limiters[slot].allow(blockStartTimeS(world), suppressed)) return;
  if (suppressed > 0)
    postFromRt(world, "%s (and %d times more since the last message)\n", reason, suppressed);
  else
    postFromRt(world, "%s\n", reason);
}

// The stages every command runs, around its own: a failing NRT stage does not end the command
// (so that the RT stage can answer /kfFail); the last stage sends /done only on success and
// still runs after a refusal, to delete what was opened for nothing.
bool wrappedStage2(World* world, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (data->stages[0] != nullptr && !data->stages[0](world, data) && !data->failed)
    failWith(data, "%s failed", data->name);
  if (data->failed) Print("%s\n", data->reason);
  return true;
}

bool wrappedStage3(World* world, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  const bool failedBefore = data->failed;
  if (!failedBefore && data->stages[1] != nullptr && !data->stages[1](world, data) && !data->failed)
    failWith(data, "%s failed", data->name);
  if (data->failed && !failedBefore) postFromRt(world, "%s\n", data->reason);
  if (data->failed) replyFailure(world, data);
  return !data->failed || data->device != nullptr || data->previous != nullptr;
}

bool wrappedStage4(World* world, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (data->extra != nullptr && data->failed) data->deleteExtra(data->extra);
  if (data->failed) {
    delete data->previous;                                                        // unpublished: nothing else holds it
    if (data->ownsDevice && data->previous != data->device) delete data->device;  // never published
    return false;
  }
  if (data->stages[2] == nullptr || data->stages[2](world, data)) return true;
  if (!data->failed) failWith(data, "%s failed", data->name);
  Print("%s\n", data->reason);
  replyFailureFromNrt(world, data);
  return false;
}

}  // namespace

bool haveDevice(CommandData* data) {
  if (data->device != nullptr) return true;
  failWith(data, "%s: no device is open at index %d", data->name, data->args.index);
  return false;
}

void failWith(CommandData* data, const char* format, ...) {
  data->failed = true;
  va_list args;
  va_start(args, format);
  std::vsnprintf(data->reason, kMaxReasonChars, format, args);
  va_end(args);
}

// RT: the failure to the notified clients, as the node reply /kfFail from the root group.
void replyFailure(World* world, int index, const char* reason) {
  float codes[kMaxReasonChars];
  int n = 0;
  for (; n < kMaxReasonChars && reason[n] != '\0'; ++n) codes[n] = static_cast<unsigned char>(reason[n]);
  // The plugin headers do not define Group; the server's starts with its Node (SC_Group.h).
  SendNodeReply(reinterpret_cast<Node*>(world->mTopGroup), index, "/kfFail", n, codes);
}

void replyFailure(World* world, const CommandData* data) { replyFailure(world, data->args.index, data->reason); }

void replySuccess(World* world, const CommandData* data) {
  float codes[kMaxReasonChars];
  int n = 0;
  for (; n < kMaxReasonChars && data->name[n] != '\0'; ++n) codes[n] = static_cast<unsigned char>(data->name[n]);
  SendNodeReply(reinterpret_cast<Node*>(world->mTopGroup), data->args.index, "/kfDone", n, codes);
}

// The cleanup of every command (RT, after its last stage; also of one refused before its
// stages): its end reply, then /kfDone unless it failed (a failure was answered already).
void freeCommand(World* world, void* raw) {
  auto* data = static_cast<CommandData*>(raw);
  if (data->onEnd != nullptr) data->onEnd(world, data);
  if (!data->failed) replySuccess(world, data);
  if (data->args.values != nullptr) RTFree(world, data->args.values);
  RTFree(world, data);
}

CommandData* newCommand(World* world, const char* name, CommandShape shape, sc_msg_iter* msg) {
  auto* data = static_cast<CommandData*>(RTAlloc(world, sizeof(CommandData)));
  if (data == nullptr) {
    char reason[kMaxReasonChars];
    std::snprintf(reason, sizeof reason, "%s: RT memory allocation failed (raise ServerOptions.memSize); refused",
                  name);
    postFromRt(world, "%s\n", reason);
    replyFailure(world, -1, reason);
    return nullptr;
  }
  data->name = name;
  data->device = data->previous = nullptr;
  data->generation = 0;
  data->replace = data->failed = data->ownsDevice = false;
  data->threadPriority = kf::kAutoPriority;
  // The audio thread's priority, for the device threads' own (ThreadScheduling): commands run in
  // the audio thread of a realtime server.
  if (world->mRealTime) kf::noteAudioThreadPriority(kf::currentThreadPriority());
  data->onEnd = nullptr;
  data->extra = nullptr;
  data->deleteExtra = nullptr;
  data->reason[0] = '\0';
  OscArgReader reader = readerOf(msg);
  char error[200];
  if (!parseCommandArgs(shape, reader, kNumDeviceSlots, data->args, allocValues, world, error, sizeof error)) {
    // Answered every time, posted at most once a second per cause (postRefusal). The device is
    // the reply ID, -1 when the device argument itself is what is wrong.
    if (data->args.index >= 0)
      failWith(data, "%s: device %d: %s; refused", name, data->args.index, error);
    else
      failWith(data, "%s: %s; refused", name, error);
    postRefusal(world, data->reason);
    replyFailure(world, data);
    freeCommand(world, data);
    return nullptr;
  }
  return data;
}

void run(World* world, void* replyAddr, CommandData* data, AsyncStageFn stage2, AsyncStageFn stage3,
         AsyncStageFn stage4) {
  data->stages[0] = stage2;
  data->stages[1] = stage3;
  data->stages[2] = stage4;
  DoAsynchronousCommand(world, replyAddr, data->name, data, wrappedStage2, wrappedStage3, wrappedStage4, freeCommand, 0,
                        nullptr);
}

// Applies the overrides to a spec and simulation settings; false (and a message) on a bad key.
bool applyOverrides(CommandData* data, kf::DeviceSpec& spec, kf::SimParams* sim, kf::ReplayOptions* replay,
                    const char* callerKey) {
  for (int i = 0; i < data->args.numOverrides; ++i) {
    const char* key = data->args.keys[i];
    const double value = kf::snapToBounds(key, data->args.overrideValues[i]);
    if (std::strcmp(key, "replace") == 0) {  // not a device setting: how to treat a taken slot
      data->replace = value != 0.0;
      continue;
    }
    if (callerKey != nullptr && std::strcmp(key, callerKey) == 0) continue;
    std::string error;
    if (std::strcmp(key, "threadPriority") == 0) {  // not a device setting: its threads'
      error = kf::checkSetting(key, value);
      if (error.empty()) {
        data->threadPriority = static_cast<int>(value);
        continue;
      }
      failWith(data, "%s: %s; not opened", data->name, error.c_str());
      return false;
    }
    if (spec.applyOverride(key, value, &error)) continue;
    // Not a device setting: perhaps a simulation or replay one. A setting one of them knows but
    // whose value is out of range is an error with that one's message.
    auto unknown = [&error] { return error.rfind("unknown", 0) == 0; };
    if (unknown() && sim != nullptr && sim->applyOverride(key, value, &error)) continue;
    if (unknown() && replay != nullptr && replay->applyOverride(key, value, &error)) continue;
    if (unknown()) error = "unknown setting '" + std::string(key) + "'";
    failWith(data, "%s: %s; not opened", data->name, error.c_str());
    return false;
  }
  std::string error;
  if (!spec.isValid(&error)) {
    failWith(data, "%s: the device settings do not fit together: %s; not opened", data->name, error.c_str());
    return false;
  }
  return true;
}

kf::DeviceOptions deviceOptionsOf(World* world, const CommandData* data) {
  kf::DeviceOptions options;
  options.thread = {data->args.index, data->threadPriority};
  options.audioPeriodS = world->mBufLength / world->mSampleRate;
  return options;
}

bool publishStage(World* world, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  // A lockstep device's time starts with the next block, as a realtime one's starts at open.
  if (data->device != nullptr && data->device->isLockstep()) data->device->setLockstepOriginS(blockStartTimeS(world));
  if (!data->replace && peekSlot(data->args.index) != nullptr) {
    // Refused: the new device is deleted by the last stage; the open one stays.
    failWith(data, "%s: device index %d is taken; close it first or open with replace", data->name, data->args.index);
    return true;
  }
  data->previous = exchangeSlot(data->args.index, data->device);
  return true;
}

bool deletePreviousStage(World*, void* raw) {  // NRT
  deleteRetired(static_cast<CommandData*>(raw)->previous);
  return true;
}

// Commands that act on the device a slot holds look it up in an RT stage that follows an NRT
// stage: an open sent just before has published its device by then (stages run in order).
bool nrtHop(World*, void*) { return true; }

bool lookUpDeviceStage(World*, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  data->device = peekSlot(data->args.index);
  return true;
}

bool unpublishStage(World*, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  data->previous = exchangeSlot(data->args.index, nullptr);
  return true;
}

}  // namespace kf::sc
