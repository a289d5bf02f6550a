// GadgetLog: what the gadget saw, timestamped on the board's side of the bus (CLOCK_MONOTONIC,
// the clock the host's steady_clock reads on the same Linux): every set-point frame received
// (its sequence, drive and what the firmware made of it; a multi set-point frame's every level),
// every change of the coil's target,
// every control request, every FunctionFS event, every status frame the host took, and the
// lateness of the 1 ms tick. Bounded: room for a fixed number of records, made at start; what
// does not fit is counted, never grown into. report() writes the records since the last report
// as text lines (one record a line, the kind first) and forgets them.
#pragma once

#include <time.h>

#include <cstdint>
#include <string>
#include <vector>

namespace kf::board::gadget {

// CLOCK_MONOTONIC in ns: the gadget's one clock.
inline int64_t monotonicNs() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<int64_t>(now.tv_sec) * 1000000000 + now.tv_nsec;
}

class GadgetLog {
 public:
  enum class Verdict : uint8_t { kApplied, kStale, kBad };

  explicit GadgetLog(size_t capacity = 1u << 18);

  void frame(int64_t timeNs, int bytes, uint16_t sequence, uint16_t drive, Verdict verdict, uint64_t validFrames);
  // A multi set-point frame's levels (2.1), after its frame record: level `index` of the frame.
  void level(int64_t timeNs, int index, uint16_t drive);
  void target(int64_t timeNs, uint16_t drive, const char* why);
  void control(int64_t timeNs, uint8_t request, uint16_t value, bool stalled);
  void event(int64_t timeNs, const char* name);
  void statusTaken(int64_t timeNs, int64_t builtNs, uint16_t lastSequence, uint16_t framesReceived);
  void tick(int64_t lateNs, uint64_t missed);
  // A status frame not taken within its tick, built anew once its cancel came back after `cancelNs`.
  void statusReplaced(int64_t cancelNs);

  // Writes the records since the last report to `path` (then the tick figures); the number of
  // frames written, or -1 when the file could not be written.
  long report(const std::string& path);

 private:
  enum class Kind : uint8_t { kFrame, kLevel, kTarget, kControl, kEvent, kStatus };
  struct Record {
    int64_t timeNs;
    int64_t otherNs;   // status: when the frame was built
    const char* text;  // target: why; event: its name (static strings)
    uint32_t count;    // frame: valid frames so far
    uint16_t a;        // frame, status: sequence; level, target: drive; control: wValue
    uint16_t b;        // frame: drive; status: frames received
    uint8_t c;         // frame: bytes; level: index; control: bRequest
    Kind kind;
    uint8_t flag;  // frame: Verdict; control: stalled
  };
  void add(const Record& record);

  std::vector<Record> records_;
  size_t used_ = 0;
  uint64_t dropped_ = 0;
  uint64_t ticks_ = 0, missedTicks_ = 0, statusReplaced_ = 0;
  int64_t maxLateNs_ = 0, maxCancelNs_ = 0;
};

}  // namespace kf::board::gadget
