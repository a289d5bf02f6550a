// The machinery every plugin command shares (DeviceCommands, MouseCommands, BoardCommands):
// arguments read and checked in the RT stage by CommandArgs (never past the packet), refusals
// posted at most once a second per cause, the stages run as SC's asynchronous commands with
// `/done cmdName` and `/kfDone` (replySuccess) on success and `/kfFail` (replyFailure) on
// failure, whatever failed: the arguments, RT memory or a stage. Every command gets exactly one
// outcome. Also the stages the open and slot commands have in common.
//
// Why `/kfDone` beside `/done`: SC's own commands answer `/done /b_alloc bufnum`, but a plugin's
// /done is sent by the server (DoAsynchronousCommand's last stage, scsynth and supernova alike)
// with the command's name only, and the plugin interface has no call that replies to the sender
// with more. So the slot comes in `/kfDone`, a node reply shaped as `/kfFail` is: node 0, reply
// ID the slot, the command's name as character codes. Two commands of one name in flight are
// then told apart by slot (an open that fails in its last stage answers after a later one's
// /done). `/done cmdName` stays for clients that wait for it.
#pragma once

#include <SC_PlugIn.hpp>

#include "CommandArgs.hpp"
#include "DeviceFactory.hpp"
#include "core/PrintfFormat.hpp"

namespace kf::sc {

constexpr int kMaxReasonChars = 200;

struct CommandData {
  const char* name;
  CommandArgs args;      // args.values: the hand script (kfOpenSim only), RTAlloc'd to its size
  kf::Device* device;    // opened by stage 2, or the target of record/status
  uint32_t generation;   // kfDriveCalibrate: the slot's generation stage 2 built the chain for
  kf::Device* previous;  // swapped out of the slot, deleted in an NRT stage
  bool replace;          // open commands: a device in the slot is closed, not refused
  int threadPriority;    // open commands: the device's threads (ThreadScheduling), kAutoPriority
  bool ownsDevice;       // open commands: `device` is theirs until published
  bool failed;           // a stage failed; `reason` says why
  char reason[kMaxReasonChars];
  AsyncStageFn stages[3];  // the command's own stages, run by the wrappers of run()
  // RT, at the very end (success or not), before the command is freed: e.g. a reply with values.
  void (*onEnd)(World* world, CommandData* data);
  float replyValues[32];  // for onEnd (kfBoardStatus)
  // A command's own object made in an NRT stage (kfDriveCalibrate: the drive chain), deleted in
  // the last NRT stage by deleteExtra, also when the command failed.
  void* extra;
  void (*deleteExtra)(void* extra);
};

// Records why the command failed; the stage wrappers post it and answer /kfFail with it.
void failWith(CommandData* data, const char* format, ...) KF_PRINTF_FORMAT(2, 3);
// NRT, after lookUpDeviceStage: true when the slot held a device; else the command fails with
// "<name>: no device is open at index <i>".
bool haveDevice(CommandData* data);
// RT: the failure to the notified clients: /kfFail, node 0, reply ID the device (-1 when the
// device argument itself was wrong, or the command has none), then the reason as character
// codes, which starts with the command's name ("kfRecord: ...").
void replyFailure(World* world, int index, const char* reason);
void replyFailure(World* world, const CommandData* data);
// RT: the success to the notified clients: /kfDone, node 0, reply ID the device (-1 for a
// command without one), then the command's name as character codes.
void replySuccess(World* world, const CommandData* data);

// RT: a command with its arguments read and checked for `shape`; null if they do not fit or RT
// memory is short (then the refusal is answered and posted).
CommandData* newCommand(World* world, const char* name, CommandShape shape, sc_msg_iter* msg);
// An SC asynchronous command from the command's own stages (2 and 4 NRT, 3 RT; see the
// wrappers for what happens on failure); frees `data` at the end.
void run(World* world, void* replyAddr, CommandData* data, AsyncStageFn stage2, AsyncStageFn stage3,
         AsyncStageFn stage4);
void freeCommand(World* world, void* raw);

// NRT: the command's settings applied to a spec, simulation and replay settings (null: not
// taken), `replace` and `threadPriority`; a setting named callerKey is left to the caller. False
// (failWith) on a bad key or value.
bool applyOverrides(CommandData* data, DeviceSpec& spec, SimParams* sim, ReplayOptions* replay = nullptr,
                    const char* callerKey = nullptr);

// Stages shared by the open commands: publish the opened device (RT; a taken slot is refused
// unless replace), delete the one it replaced (NRT).
bool publishStage(World* world, void* raw);
bool deletePreviousStage(World* world, void* raw);
// The options of a device an open command makes: its threads named after the slot, at the
// command's threadPriority; the server's block as the audio period its jitter buffer starts from.
DeviceOptions deviceOptionsOf(World* world, const CommandData* data);
// Stages of the commands that act on the slot's device: a hop to NRT, then the look-up (RT),
// or its removal from the slot (RT).
bool nrtHop(World* world, void* raw);
bool lookUpDeviceStage(World* world, void* raw);
bool unpublishStage(World* world, void* raw);

}  // namespace kf::sc
