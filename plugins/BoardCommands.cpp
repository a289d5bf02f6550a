// Asynchronous plugin commands for the friction board (device/board/PROTOCOL.md) of a device slot, on
// the machinery of CommandRunner.hpp (checked arguments, /done or /kfFail): the RT stage only
// looks the slot's device up; opening, arming, loading and closing run in NRT stages.
//
//   kfBoardOpen      index serial emulate inFlight   serial "" = the first board; emulate 1 =
//                                                    the board emulator instead of libusb;
//                                                    refused on a device that cannot carry a
//                                                    board (boardRefusal)
//   kfBoardArm       index arm                       1 arms, 0 disarms
//   kfBoardCalibrate index path                      a kf-calibration file; "" = linear
//   kfBoardClose     index                           drive 0, disarm, release, close
//   kfBoardStatus    index                           replies /kfBoardStatus (to /notify clients):
//                    index, then kBoardStatusFields values (BoardStatusField order); a device
//                    without a board answers hasBoard 0, an empty slot is refused (no reply)
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "BoardStatus.hpp"
#include "CommandRunner.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"
#include "board/EmulatedUsb.hpp"
#include "board/UsbBoardBackend.hpp"
#include "core/force/CalibrationTable.hpp"
#include "recordings/ReplayBackend.hpp"

namespace {

using namespace kf::sc;

// The values of a /kfBoardStatus reply, in order (sclang: FrictionDevice.boardStatusOf).
enum BoardStatusField {
  kHasBoard,
  kConnected,
  kArmed,
  kBoardState,
  kCurrent,
  kTemperatureC,
  kErrors,
  kSetPointsSent,
  kLate,
  kLost,
  kTimeouts,
  kPartials,
  kStalls,
  kBadStatus,
  kUnplugs,
  kReopens,
  kOnePerPump,
  kOffsetP50S,
  kForceRateHz,    // the board's: levels per 1 ms frame x 1000 (2.1: up to 8 kHz)
  kLevelsPadded,   // levels sent again: the device's next had not come
  kLevelsDropped,  // levels never sent: more than two frames were waiting
  kBoardStatusFields
};

static_assert(kBoardStatusFields <= static_cast<int>(sizeof(CommandData::replyValues) / sizeof(float)));

kf::UsbBoardBackend* boardOf(CommandData* data, std::shared_ptr<kf::ForceBackend>& holder) {
  holder = data->device->board();
  auto* board = dynamic_cast<kf::UsbBoardBackend*>(holder.get());
  if (board == nullptr) failWith(data, "%s: device %d has no board (kfBoardOpen first)", data->name, data->args.index);
  return board;
}

// --- kfBoardOpen ---------------------------------------------------------------------------

// Why `device` cannot carry a board, or null. The board is a magnet under a live puck, driven
// one set-point per ms of real time: a lockstep device (NRT rendering, a Score) runs on audio
// time, faster or slower than the clock, and a replay's puck is a recording, not the one on the
// magnet. A live puck is a real mouse or a simulated hand (the emulator's tests use one).
const char* boardRefusal(kf::Device& device) {
  if (device.isLockstep())
    return "renders in lockstep (a Score or NRT server) and a board runs in real time only: add it on a realtime "
           "server";
  if (dynamic_cast<const kf::ReplayBackend*>(&device.mouseBackend()) != nullptr)
    return "replays a recording, whose puck is not the one on the magnet: add the board to a mouse (or simulated) "
           "device";
  return nullptr;
}

bool openStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (!haveDevice(data)) return false;
  if (const char* why = boardRefusal(*data->device)) {
    failWith(data, "kfBoardOpen: device %d %s; refused", data->args.index, why);
    return false;
  }
  kf::BoardOptions options;
  const bool emulate = data->args.numbers[0] != 0.0;
  options.ids.serial = data->args.which;
  options.transfersInFlight = static_cast<int>(data->args.numbers[1]);
  options.minForceN = data->device->spec().minForceN;
  options.maxForceN = data->device->spec().maxForceN;
  // The board is asked for the device's force rate: 8 levels per 1 ms frame at 8 kHz.
  options.subSetPoints =
      static_cast<int>(std::clamp(std::lround(kf::board::kFramePeriodS / data->device->spec().forceFramePeriodS), 1L,
                                  static_cast<long>(kf::board::kMaxSubSetPoints)));
  options.thread = data->device->options().thread;
  std::unique_ptr<kf::usb::Port> port;
  if (emulate)
    port = kf::board::EmulatedUsb::create(data->args.which[0] != '\0' ? data->args.which : "KF-EMU-0001")->makePort();
  else
    port = kf::usb::makeLibusbPort();
  auto board = std::make_shared<kf::UsbBoardBackend>(std::move(port), options);
  std::string error;
  if (!board->open(error)) {
    failWith(data, "kfBoardOpen: %s", error.c_str());
    return false;
  }
  // The board replaced, if any, closes here (NRT) as the last reference goes. A new board starts
  // with the linear table: another board's table must not drive it (kfBoardCalibrate checks).
  data->device->attachBoard(board);
  data->device->setCalibration(
      kf::CalibrationTable::linear(data->device->spec().minForceN, data->device->spec().maxForceN));
  const kf::BoardTelemetry t = board->telemetry();
  Print(
      "kfBoardOpen %d board %s%s (protocol %d.%d, firmware %d.%d.%d, full scale %d mA, force at %d kHz) is "
      "disarmed\n",
      data->args.index, t.serial.empty() ? "(no serial)" : t.serial.c_str(), emulate ? " (emulated)" : "",
      t.version.protocolMajor, t.version.protocolMinor, t.version.firmwareMajor, t.version.firmwareMinor,
      t.version.firmwarePatch, t.version.fullScaleCurrentMa, t.subSetPoints);
  if (t.subSetPoints < options.subSetPoints)
    Print(
        "kfBoardOpen %d: the device frames force at %d kHz, this board plays %d kHz: it is sent the mean of each "
        "%d frames\n",
        data->args.index, options.subSetPoints, t.subSetPoints, options.subSetPoints / t.subSetPoints);
  return true;
}

void openCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfBoardOpen", CommandShape::kBoardOpen, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, openStage);
}

// --- kfBoardArm ----------------------------------------------------------------------------

bool armStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (!haveDevice(data)) return false;
  std::shared_ptr<kf::ForceBackend> holder;
  kf::UsbBoardBackend* board = boardOf(data, holder);
  if (board == nullptr) return false;
  std::string error;
  const bool arm = data->args.numbers[0] != 0.0;
  if (!(arm ? board->arm(error) : board->disarm(error))) {
    failWith(data, "kfBoardArm: %s", error.c_str());
    return false;
  }
  Print("kfBoardArm %d board %s\n", data->args.index, arm ? "armed" : "disarmed");
  return true;
}

void armCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfBoardArm", CommandShape::kFlag, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, armStage);
}

// --- kfBoardCalibrate ----------------------------------------------------------------------

bool calibrateStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (!haveDevice(data)) return false;
  const kf::DeviceSpec& spec = data->device->spec();
  kf::CalibrationTable table = kf::CalibrationTable::linear(spec.minForceN, spec.maxForceN);
  std::string error;
  if (data->args.path[0] != '\0') {
    // A table drives only the board it was measured on (CalibrationTable::checkBoard).
    const std::shared_ptr<kf::ForceBackend> holder = data->device->board();
    const auto* board = dynamic_cast<const kf::UsbBoardBackend*>(holder.get());
    if (!kf::CalibrationTable::load(data->args.path, table, error)) {
      failWith(data, "kfBoardCalibrate: %s", error.c_str());
      return false;
    }
    if (!table.checkBoard(board != nullptr, board != nullptr ? board->telemetry().serial : "", error)) {
      failWith(data, "kfBoardCalibrate: %s", error.c_str());
      return false;
    }
  }
  data->device->setCalibration(table);
  return true;
}

void calibrateCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfBoardCalibrate", CommandShape::kRecord, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, calibrateStage);
}

// --- kfBoardClose --------------------------------------------------------------------------

bool closeStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (data->device != nullptr) data->device->attachBoard(nullptr);  // the board closes here
  return true;
}

void closeCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfBoardClose", CommandShape::kIndex, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, closeStage);
}

// --- kfBoardStatus -------------------------------------------------------------------------

bool collectStatusStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  std::fill_n(data->replyValues, static_cast<int>(kBoardStatusFields), 0.0f);
  // Refused as arm and calibrate are: zeros would read as "a device without a board".
  if (!haveDevice(data)) return false;
  const kf::TelemetrySnapshot t = data->device->telemetry();
  const uint64_t pumps = t.framesPerPump[0] + t.framesPerPump[1] + t.framesPerPump[2] + t.framesPerPump[3];
  data->replyValues[kOnePerPump] = pumps > 0 ? static_cast<float>(t.framesPerPump[1] / double(pumps)) : 0.0f;
  data->replyValues[kOffsetP50S] = static_cast<float>(t.frameOffset.p50S);
  const std::shared_ptr<kf::ForceBackend> holder = data->device->board();
  const auto* board = dynamic_cast<const kf::UsbBoardBackend*>(holder.get());
  if (board == nullptr) return true;
  const kf::BoardTelemetry b = board->telemetry();
  float* v = data->replyValues;
  v[kHasBoard] = 1.0f;
  v[kConnected] = b.connected ? 1.0f : 0.0f;
  v[kArmed] = b.armed ? 1.0f : 0.0f;
  v[kBoardState] = b.haveStatus ? static_cast<float>(b.status.state) : -1.0f;
  v[kCurrent] = static_cast<float>(b.status.currentDrive / double(kf::board::kDriveFull));
  v[kTemperatureC] = static_cast<float>(b.status.temperatureCentiC / 100.0);
  v[kErrors] = static_cast<float>(b.status.errors);
  v[kSetPointsSent] = static_cast<float>(b.setPointsSent);
  v[kLate] = static_cast<float>(b.lateTransfers);
  v[kLost] = static_cast<float>(b.lostTransfers);
  v[kTimeouts] = static_cast<float>(b.timeouts);
  v[kPartials] = static_cast<float>(b.partials);
  v[kStalls] = static_cast<float>(b.stalls);
  v[kBadStatus] = static_cast<float>(b.badStatus);
  v[kUnplugs] = static_cast<float>(b.unplugs);
  v[kReopens] = static_cast<float>(b.reopens);
  v[kForceRateHz] = static_cast<float>(1000 * b.subSetPoints);
  v[kLevelsPadded] = static_cast<float>(b.subStepsPadded);
  v[kLevelsDropped] = static_cast<float>(b.subStepsDropped);
  return true;
}

// RT, at the end: the reply goes from the root group to every client that asked for
// notifications (sclang's default).
void replyStatus(World* world, CommandData* data) {
  if (data->failed) return;  // the refusal is the answer
  // The plugin headers do not define Group; the server's starts with its Node (SC_Group.h).
  SendNodeReply(reinterpret_cast<Node*>(world->mTopGroup), data->args.index, "/kfBoardStatus", kBoardStatusFields,
                data->replyValues);
}

void statusCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfBoardStatus", CommandShape::kIndex, args);
  if (data == nullptr) return;
  std::fill_n(data->replyValues, static_cast<int>(kBoardStatusFields), 0.0f);
  data->onEnd = replyStatus;
  run(world, replyAddr, data, nrtHop, lookUpDeviceStage, collectStatusStage);
}

}  // namespace

namespace kf::sc {

void postBoardStatus(int index, Device& device) {
  const uint64_t limited = device.driveLimitedFrames();
  const double heat = device.heatEstimate();
  if (limited > 0 || heat > 0.0)
    Print(
        "kfStatus %d: force path: drive-limited frames %llu, coil heat estimate at the last frame %.3f (derating from "
        "%.3f)\n",
        index, static_cast<unsigned long long>(limited), heat, 0.9 * device.spec().heatRatedDuty);
  const std::shared_ptr<ForceBackend> holder = device.board();
  const auto* board = dynamic_cast<const UsbBoardBackend*>(holder.get());
  if (board == nullptr) return;
  const BoardTelemetry t = board->telemetry();
  const board::Status& s = t.status;
  auto count = [](uint64_t value) { return static_cast<unsigned long long>(value); };
  Print(
      "kfStatus %d: board %s %s, %s, force at %d kHz; board state %s, current %.3f of full scale, %.2f degC, errors "
      "0x%04x%s\n",
      index, t.serial.empty() ? "(no serial)" : t.serial.c_str(), t.connected ? "connected" : "NOT CONNECTED",
      t.armed ? "armed" : "disarmed", t.subSetPoints,
      !t.haveStatus                             ? "unknown"
      : s.state == board::BoardState::kArmed    ? "armed"
      : s.state == board::BoardState::kDisarmed ? "disarmed"
                                                : "FAULT",
      s.currentDrive / static_cast<double>(board::kDriveFull), s.temperatureCentiC / 100.0, s.errors,
      (s.errors & board::kErrWatchdog) ? " (its watchdog tripped)" : "");
  Print(
      "kfStatus %d: board set-points sent %llu (last drive %.3f), late %llu, lost %llu (timeouts %llu, partial "
      "%llu), stalls %llu, bad status %llu, unplugs %llu, reopens %llu, resets %llu, levels padded %llu, dropped "
      "%llu%s%s%s\n",
      index, count(t.setPointsSent), t.lastDriveSent / static_cast<double>(board::kDriveFull), count(t.lateTransfers),
      count(t.lostTransfers), count(t.timeouts), count(t.partials), count(t.stalls), count(t.badStatus),
      count(t.unplugs), count(t.reopens), count(t.boardResets), count(t.subStepsPadded), count(t.subStepsDropped),
      t.transfersLeaked ? "; a transfer never came back (left allocated)" : "",
      t.lastError.empty() ? "" : "; last error ", t.lastError.c_str());
}

}  // namespace kf::sc

void registerBoardCommands() {
  DefinePlugInCmd("kfBoardOpen", openCmd, nullptr);
  DefinePlugInCmd("kfBoardArm", armCmd, nullptr);
  DefinePlugInCmd("kfBoardCalibrate", calibrateCmd, nullptr);
  DefinePlugInCmd("kfBoardClose", closeCmd, nullptr);
  DefinePlugInCmd("kfBoardStatus", statusCmd, nullptr);
}
