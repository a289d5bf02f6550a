#include "SlotTrajectory.hpp"

#include <cmath>
#include <new>

namespace kf::sc {

void addEntries(TrajectoryReconstructor& trajectory, const PositionEntry* entries, int numEntries) {
  for (int i = 0; i < numEntries; ++i) {
    const PositionEntry& e = entries[i];
    if (e.isShift)
      trajectory.addShift(e.timeS, e.dxMm, e.dyMm);
    else
      trajectory.addReport(e.timeS, e.dxMm, e.dyMm, e.flags, e.deviceTimeS);
  }
}

void SlotTrajectory::reset(const DeviceSpec& spec) {
  axes_ = spec;
  updateRateHz_ = spec.updateRateHz;
  valid_ = false;
  lastBlock_ = -1;
  xCounts_ = yCounts_ = 0;
  offsetXMm_ = offsetYMm_ = 0.0;
  positionRequested_ = false;
  reportsTaken_ = 0;
  buttons_ = lastReportButtons_ = 0;
  clock_.reset();
  for (int m = 0; m < kNumModes; ++m) {
    references_[m].~TrajectoryReconstructor();
    new (&references_[m]) TrajectoryReconstructor(updateRateHz_, static_cast<TrajectoryMode>(m));
  }
  numEntries_ = 0;
}

void SlotTrajectory::requestPosition(double xMm, double yMm) {
  positionRequested_ = true;
  requestedXMm_ = std::isfinite(xMm) ? xMm : 0.0;
  requestedYMm_ = std::isfinite(yMm) ? yMm : 0.0;
}

void SlotTrajectory::takeBlock(const BlockClock& clock, const MouseReport* reports, int numReports, bool lockstep,
                               double lockstepOriginS) {
  const bool continuous = continuesAt(clock.block);
  reportsTaken_ += numReports;
  // The references catch up with the previous block, rendered as an audio-rate reader did.
  if (continuous)
    for (TrajectoryReconstructor& reference : references_)
      reference.render(lastClock_.startS, lastClock_.sampleDurS, lastClock_.numSamples, 0.0, nullptr, nullptr, nullptr,
                       nullptr);

  numEntries_ = 0;
  auto add = [this](const PositionEntry& entry) {
    if (numEntries_ < kMaxEntries) {
      entries_[numEntries_++] = entry;
    } else {  // more reports than fit in one block (after a stall): the last one takes the rest
      entries_[kMaxEntries - 1].dxMm += entry.dxMm;
      entries_[kMaxEntries - 1].dyMm += entry.dyMm;
    }
  };
  if (positionRequested_) {
    // Re-based at the start of this block: the latest reported position becomes the request.
    const double shiftXMm = requestedXMm_ - reportedXMm();
    const double shiftYMm = requestedYMm_ - reportedYMm();
    offsetXMm_ += shiftXMm;
    offsetYMm_ += shiftYMm;
    add(PositionEntry{clock.startS, shiftXMm, shiftYMm, 0, true});
    positionRequested_ = false;
  }
  // A backlog (nobody read for a while) counts for its position only: it arrived late all at
  // once, and would teach the clock mapper a delay that is not there.
  if (!continuous) clock_.reset();
  buttons_ = numReports > 0 ? 0 : lastReportButtons_;
  for (int i = 0; i < numReports; ++i) {
    const MouseReport& r = reports[i];
    buttons_ |= r.buttons;
    lastReportButtons_ = r.buttons;
    double timeS = clock.startS;
    if (lockstep)
      timeS = r.deviceTimeS + lockstepOriginS;
    else if (continuous)
      timeS = clock_.map(r.deviceTimeS, clock.startS);
    // From absolute counts: reports lost on the way (a full queue) still count.
    double dxMm = 0.0, dyMm = 0.0;
    axes_.countsToMm(r.xCounts - xCounts_, r.yCounts - yCounts_, dxMm, dyMm);
    add(PositionEntry{timeS, dxMm, dyMm, r.flags, false, r.deviceTimeS});
    xCounts_ = r.xCounts;
    yCounts_ = r.yCounts;
  }

  if (continuous) {
    for (TrajectoryReconstructor& reference : references_) addEntries(reference, entries_, numEntries_);
  } else {
    // First look, or after blocks nobody looked: start at the puck's latest position.
    for (TrajectoryReconstructor& reference : references_) reference.resetAt(reportedXMm(), reportedYMm());
    numEntries_ = 0;
  }
  valid_ = true;
  lastBlock_ = clock.block;
  lastClock_ = clock;
}

}  // namespace kf::sc
