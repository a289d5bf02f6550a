// The plugin command of the audio drive (FrictionDrive, docs/drive-format.md), on the machinery of
// CommandRunner.hpp:
//
//   kfDriveCalibrate index path      a kf-drive file (with its magnet table); "" = no drive
//                                    (FrictionDrive outputs 0)
//
// Stage 2 (NRT) reads and checks the file and builds the chain for the slot's device (its force
// range, slew, drive and heat limits) at the server's sample rate; stage 3 (RT) publishes it in
// the slot, unless the slot's device changed meanwhile; stage 4 (NRT) deletes the chain it
// replaced, or the new one when the command failed.
#include <string>

#include "CommandRunner.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"
#include "SlotDrive.hpp"
#include "core/force/AudioDrive.hpp"

namespace {

using namespace kf::sc;

void deleteDrive(void* drive) { delete static_cast<kf::AudioDrive*>(drive); }

bool buildStage(World* world, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  // The generation first: the RT stage compares both (publishDriveIfSameDevice).
  data->generation = generationOfSlot(data->args.index);
  data->device = peekSlot(data->args.index);
  if (!haveDevice(data)) return false;
  if (data->args.path[0] == '\0') return true;  // no chain: the drive is removed
  kf::DriveCircuit circuit;
  std::string error;
  if (!kf::DriveCircuit::load(data->args.path, circuit, error)) {
    failWith(data, "kfDriveCalibrate: %s", error.c_str());
    return false;
  }
  data->extra = new kf::AudioDrive(data->device->spec(), circuit, world->mSampleRate);
  data->deleteExtra = deleteDrive;
  return true;
}

bool publishDriveStage(World*, void* raw) {  // RT
  auto* data = static_cast<CommandData*>(raw);
  // The chain was made for the device stage 2 saw; another one (closed, replaced) is refused.
  auto* chain = static_cast<kf::AudioDrive*>(data->extra);
  if (!publishDriveIfSameDevice(data->args.index, data->generation, data->device, chain)) {
    failWith(data, "kfDriveCalibrate: the device at index %d changed while the file was read; load it again",
             data->args.index);
    return true;  // stage 4 still runs, and deletes the chain
  }
  data->extra = chain;  // the chain it replaced, for stage 4
  data->deleteExtra = deleteDrive;
  return true;
}

bool deleteReplacedStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  deleteDrive(data->extra);
  data->extra = nullptr;
  return true;
}

void calibrateCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfDriveCalibrate", CommandShape::kRecord, args);
  if (data != nullptr) run(world, replyAddr, data, buildStage, publishDriveStage, deleteReplacedStage);
}

}  // namespace

void registerDriveCommands() { DefinePlugInCmd("kfDriveCalibrate", calibrateCmd, nullptr); }
