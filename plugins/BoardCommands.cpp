// Asynchronous plugin commands for the friction board (device/PROTOCOL.md) of a device slot.
// As in DeviceCommands.cpp: the RT stage only looks the slot's device up; opening, arming,
// loading and closing run in NRT stages.
//
//   kfBoardOpen      index serial emulate inFlight   serial "" = the first board; emulate 1 =
//                                                    the board emulator instead of libusb
//   kfBoardArm       index arm                       1 arms, 0 disarms
//   kfBoardCalibrate index path                      a kf-calibration file; "" = linear
//   kfBoardClose     index                           drive 0, disarm, release, close
//   kfBoardStatus    index                           replies /kfBoardStatus (to /notify clients):
//                    index, then kBoardStatusFields values (BoardStatusField order)
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "BoardStatus.hpp"
#include "CalibrationTable.hpp"
#include "DeviceSlots.hpp"
#include "EmulatedUsb.hpp"
#include "PluginShared.hpp"
#include "UsbBoardBackend.hpp"

namespace {

constexpr int kMaxTextChars = 1024;

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
  kBoardStatusFields
};

struct BoardCommand {
  const char* name;
  int index;
  int flag;                  // emulate (open), arm (arm)
  int inFlight;              // open
  char text[kMaxTextChars];  // serial or path
  kf::Device* device;
  float values[kBoardStatusFields];  // kfBoardStatus
};

BoardCommand* newCommand(World* world, const char* name, sc_msg_iter* args) {
  auto* data = static_cast<BoardCommand*>(RTAlloc(world, sizeof(BoardCommand)));
  if (data == nullptr) {
    kf::sc::postFromRt(world, "%s: RT memory allocation failed\n", name);
    return nullptr;
  }
  data->name = name;
  data->index = args->geti(-1);
  data->flag = 0;
  data->inFlight = 2;
  data->text[0] = '\0';
  data->device = nullptr;
  std::fill_n(data->values, static_cast<int>(kBoardStatusFields), 0.0f);
  if (!kf::sc::isValidSlot(data->index)) {
    kf::sc::postFromRt(world, "%s: device index %d is out of range 0..%d\n", name, data->index,
                       kf::sc::kNumDeviceSlots - 1);
    RTFree(world, data);
    return nullptr;
  }
  return data;
}

void readText(sc_msg_iter* args, BoardCommand* data) {
  const char* text = args->gets("");
  std::snprintf(data->text, kMaxTextChars, "%s", text != nullptr ? text : "");
}

void freeCommand(World* world, void* raw) { RTFree(world, raw); }

// An open sent just before has published its device by the RT stage after an NRT hop.
bool nrtHop(World*, void*) { return true; }

bool lookUpDeviceStage(World*, void* raw) {  // RT
  auto* data = static_cast<BoardCommand*>(raw);
  data->device = kf::sc::peekSlot(data->index);
  return true;
}

void run(World* world, void* replyAddr, BoardCommand* data, AsyncStageFn stage4) {
  DoAsynchronousCommand(world, replyAddr, data->name, data, nrtHop, lookUpDeviceStage, stage4, freeCommand, 0, nullptr);
}

bool haveDevice(const BoardCommand* data) {
  if (data->device != nullptr) return true;
  Print("%s: no device is open at index %d\n", data->name, data->index);
  return false;
}

kf::UsbBoardBackend* boardOf(const BoardCommand* data, std::shared_ptr<kf::ForceBackend>& holder) {
  holder = data->device->board();
  auto* board = dynamic_cast<kf::UsbBoardBackend*>(holder.get());
  if (board == nullptr) Print("%s: device %d has no board (kfBoardOpen first)\n", data->name, data->index);
  return board;
}

// --- kfBoardOpen ---------------------------------------------------------------------------

bool openStage(World*, void* raw) {  // NRT
  auto* data = static_cast<BoardCommand*>(raw);
  if (!haveDevice(data)) return false;
  kf::BoardOptions options;
  options.ids.serial = data->text;
  options.transfersInFlight = data->inFlight;
  options.minForceN = data->device->spec().minForceN;
  options.maxForceN = data->device->spec().maxForceN;
  std::unique_ptr<kf::usb::Port> port;
  if (data->flag != 0)
    port = kf::board::EmulatedUsb::create(data->text[0] != '\0' ? data->text : "KF-EMU-0001")->makePort();
  else
    port = kf::usb::makeLibusbPort();
  auto board = std::make_shared<kf::UsbBoardBackend>(std::move(port), options);
  std::string error;
  if (!board->open(error)) {
    Print("kfBoardOpen: %s\n", error.c_str());
    return false;
  }
  // The board replaced, if any, closes here (NRT) as the last reference goes.
  data->device->attachBoard(board);
  const kf::BoardTelemetry t = board->telemetry();
  Print("kfBoardOpen %d board %s%s (protocol %d.%d, firmware %d.%d.%d, full scale %d mA) is disarmed\n", data->index,
        t.serial.c_str(), data->flag != 0 ? " (emulated)" : "", t.version.protocolMajor, t.version.protocolMinor,
        t.version.firmwareMajor, t.version.firmwareMinor, t.version.firmwarePatch, t.version.fullScaleCurrentMa);
  return true;
}

void openCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  BoardCommand* data = newCommand(world, "kfBoardOpen", args);
  if (data == nullptr) return;
  readText(args, data);
  data->flag = args->geti(0);
  data->inFlight = args->geti(2);
  run(world, replyAddr, data, openStage);
}

// --- kfBoardArm ----------------------------------------------------------------------------

bool armStage(World*, void* raw) {  // NRT
  auto* data = static_cast<BoardCommand*>(raw);
  if (!haveDevice(data)) return false;
  std::shared_ptr<kf::ForceBackend> holder;
  kf::UsbBoardBackend* board = boardOf(data, holder);
  if (board == nullptr) return false;
  std::string error;
  const bool ok = data->flag != 0 ? board->arm(error) : board->disarm(error);
  if (!ok) {
    Print("kfBoardArm: %s\n", error.c_str());
    return false;
  }
  Print("kfBoardArm %d board %s\n", data->index, data->flag != 0 ? "armed" : "disarmed");
  return true;
}

void armCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  BoardCommand* data = newCommand(world, "kfBoardArm", args);
  if (data == nullptr) return;
  data->flag = args->geti(0);
  run(world, replyAddr, data, armStage);
}

// --- kfBoardCalibrate ----------------------------------------------------------------------

bool calibrateStage(World*, void* raw) {  // NRT
  auto* data = static_cast<BoardCommand*>(raw);
  if (!haveDevice(data)) return false;
  const kf::DeviceSpec& spec = data->device->spec();
  kf::CalibrationTable table = kf::CalibrationTable::linear(spec.minForceN, spec.maxForceN);
  std::string error;
  if (data->text[0] != '\0' && !kf::CalibrationTable::load(data->text, table, error)) {
    Print("kfBoardCalibrate: %s\n", error.c_str());
    return false;
  }
  data->device->setCalibration(table);
  return true;
}

void calibrateCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  BoardCommand* data = newCommand(world, "kfBoardCalibrate", args);
  if (data == nullptr) return;
  readText(args, data);
  run(world, replyAddr, data, calibrateStage);
}

// --- kfBoardClose --------------------------------------------------------------------------

bool closeStage(World*, void* raw) {  // NRT
  auto* data = static_cast<BoardCommand*>(raw);
  if (data->device != nullptr) data->device->attachBoard(nullptr);  // the board closes here
  return true;
}

void closeCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  BoardCommand* data = newCommand(world, "kfBoardClose", args);
  if (data == nullptr) return;
  run(world, replyAddr, data, closeStage);
}

// --- kfBoardStatus -------------------------------------------------------------------------

bool collectStatusStage(World*, void* raw) {  // NRT
  auto* data = static_cast<BoardCommand*>(raw);
  std::fill_n(data->values, static_cast<int>(kBoardStatusFields), 0.0f);
  if (data->device == nullptr) return true;  // replies all zeros: no device, no board
  const kf::TelemetrySnapshot t = data->device->telemetry();
  const uint64_t pumps = t.framesPerPump[0] + t.framesPerPump[1] + t.framesPerPump[2] + t.framesPerPump[3];
  data->values[kOnePerPump] = pumps > 0 ? static_cast<float>(t.framesPerPump[1] / double(pumps)) : 0.0f;
  data->values[kOffsetP50S] = static_cast<float>(t.frameOffset.p50S);
  const std::shared_ptr<kf::ForceBackend> holder = data->device->board();
  const auto* board = dynamic_cast<const kf::UsbBoardBackend*>(holder.get());
  if (board == nullptr) return true;
  const kf::BoardTelemetry b = board->telemetry();
  float* v = data->values;
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
  return true;
}

// RT, the last stage: the reply goes from the root group to every client that asked for
// notifications (sclang's default), then the command is freed.
void replyStatusAndFree(World* world, void* raw) {
  auto* data = static_cast<BoardCommand*>(raw);
  // The plugin headers do not define Group; the server's starts with its Node (SC_Group.h).
  SendNodeReply(reinterpret_cast<Node*>(world->mTopGroup), data->index, "/kfBoardStatus", kBoardStatusFields,
                data->values);
  RTFree(world, raw);
}

void statusCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  BoardCommand* data = newCommand(world, "kfBoardStatus", args);
  if (data == nullptr) return;
  DoAsynchronousCommand(world, replyAddr, data->name, data, nrtHop, lookUpDeviceStage, collectStatusStage,
                        replyStatusAndFree, 0, nullptr);
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
  Print("kfStatus %d: board %s %s, %s; board state %s, current %.3f of full scale, %.2f degC, errors 0x%04x%s\n", index,
        t.serial.c_str(), t.connected ? "connected" : "NOT CONNECTED", t.armed ? "armed" : "disarmed",
        !t.haveStatus                             ? "unknown"
        : s.state == board::BoardState::kArmed    ? "armed"
        : s.state == board::BoardState::kDisarmed ? "disarmed"
                                                  : "FAULT",
        s.currentDrive / static_cast<double>(board::kDriveFull), s.temperatureCentiC / 100.0, s.errors,
        (s.errors & board::kErrWatchdog) ? " (its watchdog tripped)" : "");
  Print(
      "kfStatus %d: board set-points sent %llu (last drive %.3f), late %llu, lost %llu (timeouts %llu, partial "
      "%llu), stalls %llu, bad status %llu, unplugs %llu, reopens %llu%s%s\n",
      index, count(t.setPointsSent), t.lastDriveSent / static_cast<double>(board::kDriveFull), count(t.lateTransfers),
      count(t.lostTransfers), count(t.timeouts), count(t.partials), count(t.stalls), count(t.badStatus),
      count(t.unplugs), count(t.reopens), t.lastError.empty() ? "" : "; last error ", t.lastError.c_str());
}

}  // namespace kf::sc

void registerBoardCommands() {
  DefinePlugInCmd("kfBoardOpen", openCmd, nullptr);
  DefinePlugInCmd("kfBoardArm", armCmd, nullptr);
  DefinePlugInCmd("kfBoardCalibrate", calibrateCmd, nullptr);
  DefinePlugInCmd("kfBoardClose", closeCmd, nullptr);
  DefinePlugInCmd("kfBoardStatus", statusCmd, nullptr);
}
