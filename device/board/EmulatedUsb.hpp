// EmulatedUsb: one emulated friction board (BoardEmulator) on an emulated bus, reached through
// usb::Port like the real one, on the steady clock: interrupt endpoints serve one transfer
// per 1 ms frame each, control requests at once. It fails as USB fails, on request: transfers
// that time out or fail at once, partial transfers, a stalled endpoint, unplugging (transfers in flight end
// with kNoDevice) and plugging back in, permission denied at open, a board that never arms,
// a bus reset or suspend, an over-current fault, a board of another protocol version, a
// stranger sharing the test IDs, callbacks that arrive late or never, an ARM whose reply comes
// late. Like libusb, a control request runs the callbacks that come due meanwhile on its
// caller's thread. It checks the host keeps libusb's transfer life cycle and thread rules
// (UsbPort.hpp): each breach is counted.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "board/BoardEmulator.hpp"
#include "board/UsbPort.hpp"

namespace kf::board {

class EmulatedUsb : public std::enable_shared_from_this<EmulatedUsb> {
 public:
  static std::shared_ptr<EmulatedUsb> create(std::string serial = "KF-EMU-0001");

  // A host-side port on this bus (the driver's side).
  std::unique_ptr<usb::Port> makePort();

  double nowS() const;  // the bus clock: seconds since create()

  // Failures.
  void unplug();
  void replug(const std::string& serial = "");  // serial: another board in its place
  void setDenyAccess(bool deny);
  void setRefuseArm(bool refuse);
  void timeOutNextOut(int count);   // these OUT transfers are never taken: kTimedOut
  void partialNextOut(int count);   // only half the bytes arrive (the board rejects them)
  void failOut(bool fail);          // OUT transfers fail at once (kError), as to a device going away
  void partialNextIn(int count);    // short status transfers
  void stallOut();                  // EP 0x01 halts until the host clears it
  void busReset();                  // the board is reset by the bus (disarmed, USB_RESET)
  void suspend();                   // the bus went idle: the same for the board
  void overCurrent(bool persists);  // the board trips to fault; `persists`: CLEAR_ERRORS cannot clear it
  void setOverCurrent(bool present);
  void setProtocolMajor(uint8_t major);
  void setProtocolMinor0();  // a 2.0 board: one set-point per frame, an 8-byte version reply
  // Every transfer's callback (completed, cancelled, unplugged) on `endpoint` (0: on every
  // endpoint) comes this much later than due: a host that frees or closes before its
  // callbacks ran is caught.
  void delayCallbacks(double seconds, uint8_t endpoint = 0);
  // While held, an ARM request's reply does not come (its caller handles events meanwhile, as
  // libusb does); armsHeld() counts the ARM requests waiting.
  void holdArmReply(bool hold);
  int armsHeld();
  // A device with the board's IDs but another interface, listed before the board.
  void addStranger(usb::InterfaceIdentity iface);
  int strangerTouches();  // opens, claims, control requests on strangers: must stay 0

  // What the board did (copies, under the lock).
  std::vector<BoardEmulator::Change> timeline();
  Status status();
  uint64_t validFrames();
  uint64_t rejectedFrames();
  BoardState state();
  uint16_t drive();
  int interfaceClaims();
  int interfaceReleases();
  int clearHalts();
  bool isOpen();  // a host holds it open
  // Breaches of the transfer life cycle: a handle closed, a transfer resubmitted, or a halt
  // cleared on its endpoint, while a transfer's callback had not run. A handle closed so is
  // leaked (kept open), as LibusbPort does.
  int closesInFlight();
  int resubmitsInFlight();
  int haltsInFlight();
  // Control requests sent, while the port had transfers in flight, from a thread other than
  // the one handling its events: libusb would run their callbacks on that thread.
  int eventsOffThread();
  // Closes that waited for transfers in flight (callbackWaitS > 0): the host waits for its own
  // before closing, so this is a second wait after it gave up.
  int closeWaits();

 private:
  friend class EmulatedPort;
  struct Pending {
    const void* owner;  // the port that submitted it
    usb::Transfer* transfer;
    double dueS;     // when it completes (cancel and unplug bring it forward); +callbackDelayS_
    int generation;  // of the plug-in it was submitted on
    bool cancelled;
    bool timeOut;
    bool partial;
    bool failed;
  };

  explicit EmulatedUsb(std::string serial);

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::string serial_;
  const double originS_;
  BoardEmulator board_;
  bool plugged_ = true;
  int generation_ = 1;
  bool denyAccess_ = false;
  bool outHalted_ = false;
  bool failOut_ = false;
  int timeOutOut_ = 0, partialOut_ = 0, partialIn_ = 0;
  double nextOutS_ = 0.0, nextInS_ = 0.0;  // the next free frame of each endpoint
  std::vector<Pending> pending_;
  int claims_ = 0, releases_ = 0, clearHalts_ = 0, openHandles_ = 0;
  double callbackDelayS_ = 0.0;
  uint8_t callbackDelayEndpoint_ = 0;
  std::vector<usb::InterfaceIdentity> strangers_;
  int strangerTouches_ = 0;
  int closesInFlight_ = 0, resubmitsInFlight_ = 0, haltsInFlight_ = 0;
  int eventsOffThread_ = 0, closeWaits_ = 0;
  bool holdArm_ = false;
  int armsHeld_ = 0;
};

}  // namespace kf::board
