// GadgetBoard: the friction board as the kernel tests meet it, the firmware's program
// kf_board_gadget (device/board/gadget/) run as a child on dummy_hcd's device controller: it is
// started with a serial and answers its console (stdin/stdout); what it saw comes back as a
// GadgetReport read from its report file. Unplug and plug are what a user does with the cable,
// done to the gadget's configfs UDC file (unbind, bind); the serial can be changed while it is
// unplugged (another board in its place).
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace kf::guest {

struct GadgetFrame {
  int64_t timeNs;
  int bytes;
  uint16_t sequence;
  uint16_t drive;
  std::string verdict;  // applied, stale, bad
  uint32_t validFrames;
  std::vector<uint16_t> levels;  // a multi set-point frame's (2.1), in order; empty for a single one
};
struct GadgetTarget {
  int64_t timeNs;
  uint16_t drive;
  std::string why;
};
struct GadgetControl {
  int64_t timeNs;
  int request;
  int value;
  bool stalled;
};
struct GadgetEvent {
  int64_t timeNs;
  std::string name;
};
struct GadgetStatusTaken {
  int64_t timeNs;
  int64_t builtNs;
  uint16_t lastSequence;
  uint16_t framesReceived;
};

struct GadgetReport {
  std::vector<GadgetFrame> frames;
  std::vector<GadgetTarget> targets;
  std::vector<GadgetControl> controls;
  std::vector<GadgetEvent> events;
  std::vector<GadgetStatusTaken> statuses;
  uint64_t ticks = 0, missedTicks = 0, dropped = 0;
  uint64_t statusReplaced = 0;    // status frames not taken within their tick, built anew
  int64_t statusCancelMaxNs = 0;  // the longest a replaced frame's cancel took to come back
  int64_t tickLateMaxNs = 0;

  std::vector<GadgetFrame> applied() const;  // the frames the firmware took
  // The controls of one request (0x02 ARM, 0x03 DISARM, 0x04 CLEAR_ERRORS ...).
  std::vector<GadgetControl> controlsOf(int request) const;
  bool hasEvent(const std::string& name) const;
};

class GadgetBoard {
 public:
  static constexpr const char* kSerial = "KF-GADGET-0001";

  // Starts kf_board_gadget with these extra arguments and waits until the host has configured it
  // and udev has handled its node (throws with its words if it did not start).
  explicit GadgetBoard(const std::string& serial = kSerial, const std::vector<std::string>& arguments = {});
  ~GadgetBoard();  // quit, waited for: the gadget is gone
  GadgetBoard(const GadgetBoard&) = delete;
  GadgetBoard& operator=(const GadgetBoard&) = delete;

  // One console command; its answer (throws unless it starts with "ok").
  std::string command(const std::string& line);
  // What the gadget saw since the last report.
  GadgetReport report();
  void unplug();
  void plug();  // and waits as the constructor does
  // Waits until the host has the board configured (sysfs: bConfigurationValue 1) and udev has
  // handled it; false after the hang guard.
  bool waitConfigured();
  void setSerial(const std::string& serial);  // while unplugged
  const std::string& udc() const { return udc_; }

 private:
  std::string gadgetDir() const;
  std::string whereItWaits() const;

  pid_t pid_ = -1;
  int toGadget_ = -1;
  int fromGadget_ = -1;
  std::string udc_;
  std::string serial_;
  std::string buffered_;
  int reports_ = 0;
};

}  // namespace kf::guest
