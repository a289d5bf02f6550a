// TrajectoryReconstructor: the puck's position and speed at audio rate, from displacement
// reports that arrive every T = 1 / updateRate (8 ms at the paper's 125 Hz).
//
// Reports come in as (audio time, dx mm, dy mm) — the caller maps device time onto audio
// time (DeviceClockMapper) and counts onto mm. The absolute position is summed in double;
// after the last report has played out, every mode sits exactly on that sum.
//
// One rule covers the three modes. A report at time ta moves the anchor to the new reported
// position A, and the output is
//     p(t) = A + v * e(t - ta) + c * w(t - ta)
// where c = (position just before the report) - A keeps p continuous and w fades it out.
//   Hold:       w = 0, e = 0: p steps to each reported position.
//   Linear:     w = 1 - s/T over one interval, e = 0: the paper's "linearly interpolating
//               over the current update interval"; costs one interval (T) of lag.
//   Predictive: as Linear, plus e(s) = s up to 1.5 T with v = dx / T of the latest report:
//               the new position is reached at ta and the motion carried on. Extrapolation
//               stops after 1.5 T (a late report, or a stop: mice send nothing when still),
//               holds until 2 T and is taken back over the next T, so a stop overshoots by
//               at most v * 1.5 T and then settles exactly on A.
// Speed output (all modes): the latest report's dx / T — the paper's speed signal, in steps
// of one count per interval — held for 2 T, then faded to 0 over T when no reports come.
//
// T is measured from the reports (ReportRateEstimator, snapped to a USB rate when near one): a
// mouse may report at any rate from 125 Hz to 8 kHz whatever the device spec assumed. The
// constructor's rate stands until the measured one differs from it by more than kRateBand (the
// rates mice use are a factor of 2 apart, so jitter never crosses it); T changes only at a
// report, so p stays continuous.
//
// Reports wait in a fixed queue until rendering reaches their time, so several reports in one
// block are taken in order at their own times. A report whose time has already been rendered
// is taken at the next sample (p stays continuous; its lateness becomes lag). Nothing here
// allocates. render() works in runs between report takes: within a run each branch of the rule
// holds for one stretch of samples, filled by a loop of its own (bit for bit the per-sample rule).
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "ReportRateEstimator.hpp"

#include "PaperProfile.hpp"

namespace kf {

enum class TrajectoryMode : int { Hold = 0, Linear = 1, Predictive = 2 };

// 0 hold, 1 linear, 2 predictive; anything else reads linear (the paper's).
TrajectoryMode trajectoryModeFromCode(int code);

class TrajectoryReconstructor {
 public:
  explicit TrajectoryReconstructor(double updateRateHz = paper::device::updateRateHz,
                                   TrajectoryMode mode = TrajectoryMode::Linear);

  // Takes effect at the next report, so the output never jumps because of it.
  void setMode(TrajectoryMode mode) { nextMode_ = mode; }
  TrajectoryMode mode() const { return nextMode_; }

  // Back to position (0, 0), at rest, no pending reports.
  void reset();
  // The same at position (xMm, yMm): a reader that joins a moving puck starts where it is.
  void resetAt(double xMm, double yMm);

  // Reports in order of time (an earlier time than the previous report's is taken as that
  // one's). flags: ReportFlag bits (kAfterLoss counts a loss). If the queue is full the
  // displacement is merged into the newest pending report, so no distance is lost.
  // sourceTimeS: the report's own timestamp (the device's clock), from which the update rate
  // is measured; mapped audio times are not fit for that (a clock mapping that corrects
  // itself spreads reports closer). NaN: reportTimeS is used.
  void addReport(double reportTimeS, double dxMm, double dyMm, uint32_t flags = 0,
                 double sourceTimeS = std::numeric_limits<double>::quiet_NaN());
  // Moves the coordinates by (dxMm, dyMm) from the next sample rendered on (timeS, the block's
  // start), ahead of any report still pending: a re-basing (zero, set position), not a
  // movement, so the output steps by exactly that and speed and interpolation go on as before.
  // Not in order with the reports: those pending may be mapped ahead of the audio clock (after
  // a stall of the audio thread the clock mapper spreads the catch-up), and a shift queued
  // behind them re-based the readers 0.14 s after the request after a stall of 0.3 s
  // (test_slot_trajectory), 0.16 s after kfZero had answered without realtime scheduling
  // (test_one_device). A shift commutes with the reports (they are displacements), so the
  // position after them is the same.
  void addShift(double timeS, double dxMm, double dyMm);

  // Sample i is at startTimeS + i * sampleDurS; times should increase from call to call.
  // originMm is subtracted from x in double before the float output (y is not shifted).
  // Any output pointer may be null.
  void render(double startTimeS, double sampleDurS, int numSamples, double originMm, float* xMm, float* yMm,
              float* vxMmPerS, float* vyMmPerS);
  // The same with an origin for each axis.
  void render(double startTimeS, double sampleDurS, int numSamples, double originXMm, double originYMm, float* xMm,
              float* yMm, float* vxMmPerS, float* vyMmPerS);

  // T in use: the nominal one, or the measured one when it differs by more than kRateBand.
  double updateIntervalS() const { return intervalS_; }
  double nominalIntervalS() const { return nominalIntervalS_; }
  // 0 until enough reports were seen.
  double measuredRateHz() const { return rate_.rateHz(); }
  static constexpr double kRateBand = 0.25;
  // Sum of the displacements of all reports taken so far (exact, double).
  double reportedXMm() const { return axes_[0].anchorMm; }
  double reportedYMm() const { return axes_[1].anchorMm; }
  // Position and speed at the last rendered sample, in double, origin not subtracted.
  double renderedXMm() const { return renderedMm_[0]; }
  double renderedYMm() const { return renderedMm_[1]; }
  double renderedSpeedXMmPerS() const { return renderedSpeedMmPerS_[0]; }
  double renderedSpeedYMmPerS() const { return renderedSpeedMmPerS_[1]; }

  int pendingReports() const { return pendingCount_; }
  int64_t reportsTaken() const { return reportsTaken_; }
  int64_t reportsAfterLoss() const { return reportsAfterLoss_; }
  int64_t reportsMerged() const { return reportsMerged_; }

 private:
  static constexpr int kQueueCapacity = 64;  // 0.5 s of 125 Hz reports
  static constexpr int kMaxRun = 256;        // samples rendered with one stack buffer of phases

  struct Pending {
    double timeS;
    double dMm[2];
  };
  struct Axis {
    double anchorMm = 0.0;      // reported position: the exact sum of displacements
    double speedMmPerS = 0.0;   // dx / T of the latest report
    double correctionMm = 0.0;  // c: position before the latest report minus the anchor
  };

  // Sample i of a render() call is at startS + i * durS: one expression wherever it is needed,
  // so every comparison with a sample's time gives what the per-sample rule gives.
  struct SampleClock {
    double startS, durS;
    double timeS(int i) const { return startS + i * durS; }
  };
  // s: the time since the anchor in intervals T.
  struct Phase {
    SampleClock clock;
    double anchorS, intervalS;
    double at(int i) const { return (clock.timeS(i) - anchorS) / intervalS; }
    // at(k) into out[k - base] for k in [from, to): a loop the compiler vectorises.
    void fill(double* out, int base, int from, int to) const {
      for (int k = from; k < to; ++k) out[k - base] = at(k);
    }
  };
  struct Outputs {
    float* positionMm[2];
    float* speedMmPerS[2];
    double originMm[2];
  };

  void enqueue(double timeS, double dxMm, double dyMm);
  void take(const Pending& report, double nowS);
  void takeDueReports(const SampleClock& clock, int i);
  int endOfRun(const SampleClock& clock, int i, int numSamples) const;
  void renderRun(const SampleClock& clock, int from, int to, const Outputs& out);
  // The output at phase s (see the header comment); render() fills whole runs with the same.
  double positionAt(const Axis& axis, double s) const;
  double speedAt(const Axis& axis, double s) const;
  // Anchor plus extrapolation plus the fading correction (p(t) above); e and fade in T. Here,
  // so that render's loops inline it (and vectorise).
  double blend(const Axis& axis, double extrapolateT, double fade) const {
    return axis.anchorMm + axis.speedMmPerS * (extrapolateT * intervalS_) + axis.correctionMm * fade;
  }

  double nominalIntervalS_;
  double intervalS_;
  ReportRateEstimator rate_;
  TrajectoryMode mode_;
  TrajectoryMode nextMode_;
  std::array<Axis, 2> axes_{};
  double anchorTimeS_ = 0.0;
  bool hasAnchor_ = false;
  double lastRenderTimeS_ = 0.0;
  bool hasRendered_ = false;
  double renderedMm_[2] = {0.0, 0.0};
  double renderedSpeedMmPerS_[2] = {0.0, 0.0};

  std::array<Pending, kQueueCapacity> queue_{};
  int pendingHead_ = 0;
  int pendingCount_ = 0;
  double lastQueuedTimeS_ = 0.0;

  int64_t reportsTaken_ = 0;
  int64_t reportsAfterLoss_ = 0;
  int64_t reportsMerged_ = 0;
};

}  // namespace kf
