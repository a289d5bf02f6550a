// SlotTrajectory: one position per device, however many FrictionMouseIn read it.
//
// The audio side of a slot, run once per block by the first reader of that block (audio
// thread only, nothing allocates): it takes the block's reports, maps their device times onto
// audio time with one clock mapper for the slot, and turns their absolute counts (Device keeps
// them since open) into position entries: displacements in mm, and shifts when the position is
// re-based (kfZero). Every reader feeds the same entries to its TrajectoryReconstructor.
//
// It also keeps one reference reconstructor per interpolation mode, rendered over every block
// exactly as an audio-rate reader renders it. A reader that starts (or meets a new device)
// copies the reference of its mode, so it starts where the puck is and from then on agrees
// with every other reader of that mode to the sample: same state, same entries, same times.
//
// Blocks in which no reader looked at the slot break the chain: the next look starts the
// references again at the latest absolute position (the backlog of reports is taken for its
// position only).
#pragma once

#include <cstdint>
#include <limits>

#include "DeviceClockMapper.hpp"
#include "TrajectoryReconstructor.hpp"
#include "core/spec/DeviceSpec.hpp"
#include "core/spec/Report.hpp"

namespace kf::sc {

// The full-rate block being computed: block counter, start time (audio seconds), duration of
// a sample and number of samples.
struct BlockClock {
  int64_t block = 0;
  double startS = 0.0;
  double sampleDurS = 1.0 / 48000.0;
  int numSamples = 64;
};

struct PositionEntry {
  double timeS = 0.0;  // audio time
  double dxMm = 0.0;
  double dyMm = 0.0;
  uint32_t flags = 0;  // ReportFlag bits
  bool isShift = false;
  double deviceTimeS = std::numeric_limits<double>::quiet_NaN();  // the report's own time stamp
};

// Feeds the entries to a reader's reconstructor in order.
void addEntries(TrajectoryReconstructor& trajectory, const PositionEntry* entries, int numEntries);

class SlotTrajectory {
 public:
  static constexpr int kMaxEntries = 256;
  static constexpr int kNumModes = 3;

  // A new device (or none): position 0, no history.
  void reset(const DeviceSpec& spec);

  // Whether this block has been taken already.
  bool hasBlock(int64_t block) const { return valid_ && lastBlock_ == block; }
  // Whether the block before this one was taken: a reader has been reading without a gap.
  bool continuesAt(int64_t block) const { return valid_ && lastBlock_ == block - 1; }

  // The first reader of a block: `reports` are all the reports popped this block (oldest
  // first). lockstep: device time + lockstepOriginS is audio time; realtime: mapped.
  void takeBlock(const BlockClock& clock, const MouseReport* reports, int numReports, bool lockstep,
                 double lockstepOriginS);

  // From the next block taken on, the latest reported position reads (xMm, yMm) for every
  // reader (audio thread: the RT stage of kfZero).
  void requestPosition(double xMm, double yMm);

  const PositionEntry* entries() const { return entries_; }
  int numEntries() const { return numEntries_; }
  // State after the previous block with this block's entries added: what a reader starting
  // in this block copies before it renders.
  const TrajectoryReconstructor& reference(TrajectoryMode mode) const { return references_[modeIndex(mode)]; }

  // The position of the latest report (mm, re-basing applied) and its speed (the report's
  // displacement over one update interval), for status and sclang.
  double reportedXMm() const { return mm(xCounts_, yCounts_, true) + offsetXMm_; }
  double reportedYMm() const { return mm(xCounts_, yCounts_, false) + offsetYMm_; }
  int64_t lastBlock() const { return lastBlock_; }
  // The buttons (bit i = button i + 1) of this block: those down in any of its reports, so a
  // click shorter than a block still shows; with no report in the block, the last report's.
  uint32_t buttons() const { return buttons_; }
  // Reports handed to takeBlock since reset (a backlog beyond the buffer counts as one).
  int64_t reportsTaken() const { return reportsTaken_; }

 private:
  static int modeIndex(TrajectoryMode mode) { return static_cast<int>(mode); }
  // The mouse's counts on the surface's x (or y): count sizes, swap and signs of the spec.
  double mm(int64_t xCounts, int64_t yCounts, bool x) const {
    double xMm = 0.0, yMm = 0.0;
    axes_.countsToMm(xCounts, yCounts, xMm, yMm);
    return x ? xMm : yMm;
  }

  DeviceSpec axes_;  // its countMm, countMmY, swapXY, signX, signY
  double updateRateHz_ = 125.0;
  bool valid_ = false;  // a block was taken since reset
  int64_t lastBlock_ = -1;
  BlockClock lastClock_;
  int64_t xCounts_ = 0;
  int64_t yCounts_ = 0;
  double offsetXMm_ = 0.0;  // kfZero re-basing
  double offsetYMm_ = 0.0;
  bool positionRequested_ = false;
  double requestedXMm_ = 0.0;
  double requestedYMm_ = 0.0;
  DeviceClockMapper clock_;
  TrajectoryReconstructor references_[kNumModes] = {TrajectoryReconstructor(125.0, TrajectoryMode::Hold),
                                                    TrajectoryReconstructor(125.0, TrajectoryMode::Linear),
                                                    TrajectoryReconstructor(125.0, TrajectoryMode::Predictive)};
  PositionEntry entries_[kMaxEntries];
  int numEntries_ = 0;
  int64_t reportsTaken_ = 0;
  uint32_t buttons_ = 0;
  uint32_t lastReportButtons_ = 0;
};

}  // namespace kf::sc
