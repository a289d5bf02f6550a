// UsbBoardBackend: the friction board (device/board/PROTOCOL.md) as a ForceBackend, through a
// usb::Port (libusb, or the emulator in tests). One event thread of its own keeps a few
// set-point OUT transfers in flight, each filled with the latest drive level when it is
// (re)submitted, and one status IN transfer. Partial, stalled and timed-out transfers are
// counted and retried (a stalled endpoint once its transfers are back and its halt cleared);
// kNoDevice is an unplug: every callback is waited for, the handle dropped and the board looked
// for again, and a board found again stays disarmed until armed again. A transfer is reused or
// freed only after its callback ran. open and arm send CLEAR_ERRORS (a reset is reported once,
// a fault that persists refuses the ARM); ARM starts the drive from off, so the device's slew
// limiter brings it up (takeRestartFromOff). close(): cancel, wait for the callbacks, one
// set-point of drive 0, DISARM, release, close. commandDrive/driveOff are lock-free (the
// device thread, or the audio thread in lockstep); open, close, arm and disarm run on a
// non-realtime thread, and once the event thread runs their control requests are sent by it
// (a synchronous request runs transfer callbacks on the thread that sends it: UsbPort.hpp).
// Force faster than 1 kHz (BoardOptions::subSetPoints > 1): the device's frames queue in a ring,
// and each set-point transfer carries the next of them as a multi set-point frame (protocol 2.1)
// when the board plays as many, else their mean as one set-point (a 2.0 board: 1 kHz).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "board/BoardProtocol.hpp"
#include "board/UsbPort.hpp"
#include "core/ForceBackend.hpp"
#include "core/threads/PiMutex.hpp"
#include "core/threads/ThreadScheduling.hpp"

namespace kf {

struct BoardOptions {
  usb::DeviceIds ids{
      board::kVendorId,
      board::kProductId,
      "",
      {board::kInterfaceNumber, board::kInterfaceClass, board::kInterfaceSubclass, board::kInterfaceProtocol}};
  int transfersInFlight = 2;  // set-points queued on EP 0x01 (1..4): each ~1 ms of latency
  unsigned transferTimeoutMs = 20;
  double reopenPeriodS = 0.25;   // after an unplug, how often to look for the board
  double lateTransferS = 0.002;  // a set-point completing later than this after the previous
  // A transfer whose callback has not come back this long after it was cancelled is given up:
  // leaked, never freed, and the board cannot be opened again until the server restarts.
  // libusb calls back every cancelled transfer, so this only bounds a broken stack.
  double callbackWaitS = 10.0;
  // commandForce (no drive given): the linear map of an uncalibrated board.
  double minForceN = 0.14;
  double maxForceN = 1.4;
  // Drive levels the device makes per 1 ms frame (1 kHz force: 1; 8 kHz: 8). The board is sent
  // as many per frame as it plays (the largest divisor of this up to its maxSubSetPoints), each
  // the mean of the device's levels it stands for.
  int subSetPoints = 1;
  ThreadRequest thread;  // the event thread (kf-usb-<slot>): the device's request
};

struct BoardTelemetry {
  bool connected = false;
  bool armed = false;       // the host's side: set-points carry the drive only when armed
  bool haveStatus = false;  // a valid status frame arrived since (re)connecting
  board::Status status;     // the last valid one
  board::VersionReply version;
  std::string serial;
  std::string lastError;
  uint16_t lastSequenceSent = 0;
  uint16_t lastDriveSent = 0;
  int subSetPoints = 1;          // drive levels per frame sent to this board (2.1: up to 8)
  uint64_t subStepsPadded = 0;   // levels sent again because the device's next had not come
  uint64_t subStepsDropped = 0;  // levels never sent: more than two frames were waiting
  uint64_t setPointsSent = 0;    // completed OUT transfers
  uint64_t lateTransfers = 0;    // completed later than lateTransferS after the previous one
  uint64_t lostTransfers = 0;    // timed out, partial or failed
  uint64_t timeouts = 0;
  uint64_t partials = 0;
  uint64_t stalls = 0;
  uint64_t badStatus = 0;  // short or damaged status frames
  uint64_t unplugs = 0;
  uint64_t reopens = 0;
  uint64_t boardResets = 0;      // power-on, bus resets, suspends the board reported (CLEAR_ERRORS)
  board::ClearReply lastClear;   // the last CLEAR_ERRORS answer
  bool transfersLeaked = false;  // a callback never came back: its transfer was never freed
};

class UsbBoardBackend : public ForceBackend {
 public:
  UsbBoardBackend(std::unique_ptr<usb::Port> port, BoardOptions options = {});
  ~UsbBoardBackend() override;
  UsbBoardBackend(const UsbBoardBackend&) = delete;
  UsbBoardBackend& operator=(const UsbBoardBackend&) = delete;

  // Finds, opens and claims the board, checks its protocol version, starts the event thread.
  // Disarmed. False with a message (no board, permission denied, busy, wrong version).
  bool open(std::string& error);
  // The clean shutdown above. Idempotent; also from the destructor.
  void close();
  bool arm(std::string& error);
  bool disarm(std::string& error);

  void commandForce(double timeS, float forceN) override;
  void commandDrive(double timeS, float forceN, float driveLevel) override;
  void driveOff() override;
  bool takeRestartFromOff() override;

  BoardTelemetry telemetry() const;
  ThreadScheduling threadScheduling() const { return threadScheduling_.load(); }
  uint16_t latestDrive() const { return static_cast<uint16_t>(latestDrive_.load(std::memory_order_relaxed) & 0xFFFFu); }

 private:
  static constexpr int kMaxInFlight = 4;
  static constexpr int kRingSize = 64;  // the device's drive levels waiting: 8 ms at 8 kHz
  // In latestDrive_ above the 16 drive bits: ARM happened and the device has not yet reset its
  // slew limiter; until it has, frames store drive 0 (they were computed before the reset).
  static constexpr uint32_t kRestartPending = 1u << 16;

  // A control request as the event thread sends it for another thread.
  struct ControlRequest {
    uint8_t requestType = 0;
    uint8_t request = 0;
    uint16_t value = 0;
    uint8_t* data = nullptr;
    uint16_t length = 0;
    int moved = 0;
    usb::Result result = usb::Result::kOther;
    bool done = false;
  };

  // Sends a control request on the event thread: directly there (or before it started), else
  // posted to it and waited for.
  usb::Result control(uint8_t requestType, uint8_t request, uint16_t value, uint8_t* data, uint16_t length, int* moved);
  void serveControl();  // event thread: sends the posted request, if any
  static void onTransfer(usb::Transfer& transfer);
  void onSetPoint(usb::Transfer& transfer);
  void onStatus(usb::Transfer& transfer);
  void run();
  bool connectLocked(std::string& error);  // portMutex_ held
  // CLEAR_ERRORS (through control()): what was set and what persists, counted in the telemetry.
  bool clearErrorsLocked(board::ClearReply& reply, std::string& error);
  void useEndpoints(const usb::InterfaceEndpoints& endpoints);  // the transfers' endpoints
  void submitSetPoint(int slot);
  // The frame's drive levels when the device makes more than one per frame: the next groups of
  // the ring, each group's mean one level; false when the single latest level is to go.
  bool nextSubSetPoints(board::MultiSetPoint& frame);
  // The levels queued so far are never sent (an off, ARM's restart): any thread, signal-safe.
  void voidQueuedLevels();
  void submitStatus();
  void submitIdle();
  // After a transfer failed at once: no transfer is sent before retryAfterS_ (true: not now).
  bool failedAtOnce(usb::TransferStatus status);
  void markUnplugged();
  void dropHandle();
  bool anyInFlight() const;
  bool anyOutInFlight() const;
  // Runs events until every callback ran (however long their timeouts); false (and the
  // transfers leaked, never freed) if one has not come back after options_.callbackWaitS.
  bool waitForTransfers();
  void cancelAll();
  void shutdownLink();
  void setError(const std::string& error);

  std::unique_ptr<usb::Port> port_;
  const BoardOptions options_;
  // What connectLocked looks for: the options' IDs, and once a board was opened, its serial,
  // so that after an unplug the same board is opened again, never another in its place (its
  // calibration table is that board's).
  usb::DeviceIds ids_;
  std::mutex portMutex_;  // open/claim/release/close: by open() before the event thread, then by it

  // Event thread only (and open() before it starts).
  usb::InterfaceEndpoints endpoints_;  // of the open board's interface
  usb::Transfer outTransfers_[kMaxInFlight];
  bool outBusy_[kMaxInFlight] = {};
  usb::Transfer statusTransfer_;
  bool statusBusy_ = false;
  usb::Transfer zeroTransfer_;
  bool zeroBusy_ = false;
  uint16_t sequence_ = 0;
  double lastOutDoneS_ = -1.0;
  bool haltOut_ = false;  // EP 0x01 stalled: cleared once no OUT transfer is in flight
  bool haltIn_ = false;   // EP 0x81 likewise
  bool unplugged_ = false;
  bool leaked_ = false;                               // a transfer was given up: the board is not opened again
  static constexpr double kRetryAfterErrorS = 0.001;  // a set-point period
  double retryAfterS_ = 0.0;                          // after a transfer failed at once, nothing is sent before this
  double nextReopenS_ = 0.0;

  std::atomic<uint32_t> latestDrive_{0};  // drive bits, and kRestartPending
  // The device's drive levels in order (subSetPoints > 1): one writer, the thread that commands
  // (the device's, under its lock); read by the event thread. Levels before voidBefore_ are
  // never sent (computed before an off or ARM's restart).
  std::atomic<uint16_t> ring_[kRingSize] = {};
  std::atomic<uint64_t> written_{0};
  std::atomic<uint64_t> voidBefore_{0};
  uint64_t taken_ = 0;             // event thread: the ring's levels up to here were sent
  std::atomic<uint64_t> offs_{0};  // offs and restarts: a held level is forgotten
  uint64_t seenOffs_ = 0;          // event thread: offs_ when last read
  uint16_t heldLevel_ = 0;         // event thread: the last level sent from the ring
  int subSetPoints_ = 1;           // event thread (and open): levels per frame this board is sent
  int levelsPerSubSetPoint_ = 1;
  std::atomic<bool> armed_{false};
  std::atomic<bool> connected_{false};
  std::atomic<bool> stopping_{false};
  std::atomic<bool> opened_{false};
  std::thread thread_;
  ThreadSchedulingCell threadScheduling_;
  std::mutex commandMutex_;  // arm and disarm, one at a time (never held by the event thread)
  std::mutex wakeMutex_;     // the reconnect wait, and the posted control request
  std::condition_variable wake_;
  std::condition_variable controlDone_;
  ControlRequest* controlRequest_ = nullptr;  // posted, not yet sent
  bool eventThreadServes_ = false;            // posted requests are sent by the event thread
  std::atomic<std::thread::id> eventThreadId_{};

  // Shared by the realtime event thread and status readers at normal priority (PiMutex.hpp).
  mutable PiMutex telemetryMutex_;
  BoardTelemetry telemetry_;
};

}  // namespace kf
