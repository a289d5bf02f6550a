// FunctionFsBoard: the board's firmware (BoardFirmware) behind Linux's FunctionFS, the other
// transport beside the emulator's: a USB device port (a board's UDC, or dummy_hcd) carries the
// board's interface, and one thread runs what a microcontroller's interrupts and main loop would:
//   - ep0: FunctionFS's events (bind, enable, disable, suspend, unbind) and the vendor control
//     requests, answered by the firmware (a STALL where it refuses);
//   - EP 0x01: set-points, read through kernel AIO with a few reads queued (so that the host's
//     queued transfers are taken back to back), each timestamped as it is reaped and given to
//     the firmware;
//   - the 1 ms tick (a timerfd): the firmware's timers (the watchdog), and the status frame on
//     EP 0x81 (PROTOCOL.md 7.1): at most one queued, built on the tick after the previous one
//     was taken, and replaced (cancelled, built again) when the host has not taken it by the
//     next tick, so that a frame the host reads is never more than 1 ms old; filling it never
//     waits on the host.
// Everything it sees goes to the GadgetLog. Test hooks a console can call between events: stop
// and resume reading set-points (a board that stops reading), halt an endpoint.
#pragma once

#include <libaio.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "board/BoardFirmware.hpp"
#include "board/gadget/GadgetLog.hpp"

namespace kf::board::gadget {

class FunctionFsBoard {
 public:
  FunctionFsBoard(std::string functionFsDir, BoardFirmware& firmware, GadgetLog& log);
  ~FunctionFsBoard();
  FunctionFsBoard(const FunctionFsBoard&) = delete;
  FunctionFsBoard& operator=(const FunctionFsBoard&) = delete;

  // Writes the descriptors and strings to ep0, opens the endpoints, starts AIO and the tick.
  // Then the gadget can be bound to a device controller. False with the reason.
  bool open(std::string& error);
  // The loop, until onReadable (called when one of extraFds is readable) returns false.
  void run(const std::vector<int>& extraFds, const std::function<bool(int fd)>& onReadable);

  // Between events, on the loop's thread:
  void setReading(bool reading);  // off: the queued reads are cancelled, the host's OUT transfers wait
  // Halts EP 0x01 (out) or EP 0x81: the host's transfers on it STALL until it clears the halt.
  bool halt(bool out, std::string& error);
  bool enabled() const { return enabled_; }

  static int64_t nowNs();  // CLOCK_MONOTONIC

 private:
  static constexpr int kQueuedReads = 4;
  struct Read {
    iocb cb{};
    uint8_t buffer[64] = {};
    bool queued = false;
  };
  struct StatusWrite {
    iocb cb{};
    uint8_t frame[kStatusSize] = {};
    bool queued = false;
    bool cancelling = false;
    int64_t builtNs = 0;
    int64_t cancelledNs = 0;  // when its replacement began
    Status status;
  };

  void onEp0();
  void onSetup(uint8_t requestType, uint8_t request, uint16_t value, uint16_t length);
  void onCompletions();
  void onRead(Read& read, long result);
  void onStatus(long result);
  void onTick();
  void onStep();        // the step timer: the frame's next level is due
  void armStepTimer();  // for the firmware's next level, or disarmed when none is in play
  void queueReads();
  void submitStatus();
  void cancel(iocb& cb);
  double seconds(int64_t ns) const { return static_cast<double>(ns) * 1e-9; }

  const std::string dir_;
  BoardFirmware& firmware_;
  GadgetLog& log_;
  int ep0_ = -1, out_ = -1, in_ = -1, events_ = -1, timer_ = -1;
  int stepTimer_ = -1;  // one-shot, at the next level of a multi set-point frame (125 us apart)
  io_context_t aio_ = nullptr;
  Read reads_[kQueuedReads];
  StatusWrite status_;
  bool enabled_ = false;
  bool reading_ = true;
  int64_t nextTickNs_ = 0;
};

}  // namespace kf::board::gadget
