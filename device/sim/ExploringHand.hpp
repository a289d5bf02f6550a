// ExploringHand: a participant exploring a strip of the surface along x as the paper's subjects
// were asked to (section 4.1: "speeds from quite slow to fast"), pushing with a force rather
// than following a position script, so that friction slows it where friction is high.
//
// The participant sweeps the strip back and forth, turning at its ends, at a speed it intends
// that steps from slow to fast (geometric steps, `tierS` each, then again from slow). Its push
// along the intended direction is what it has learnt to expect of the surface's resistance
// plus a correction proportional to how far it falls short of the intended speed (gain), within
// what a fingertip pushes (maxPushN). The expected resistance is the shortfall's integral with
// the time constant adaptS (a hand adapts within about a second, not within a millisecond): a
// constant friction is learnt and then no longer slows the puck, while friction that changes
// along the strip faster than that binds the puck where it is high, so it dwells there. Where the
// puck is held (friction above the push), the participant presses harder, by maxPushN per adaptS,
// until it slides, as a hand does.
#pragma once

namespace kf {

struct ExploreSettings {
  double fromMm = 0.0, toMm = 0.0;            // the strip, fromMm < toMm
  double slowMmPerS = 0.0, fastMmPerS = 0.0;  // the intended speeds, 0 < slow <= fast
  double tiers = 1.0;                         // speed steps from slow to fast, whole, 1..100
  double tierS = 0.0;                         // time at each speed step, > 0
  double maxPushN = 0.0;                      // the strongest push, > 0
  double gainNSPerM = 0.0;                    // push per speed shortfall (N per m/s), > 0
  double adaptS = 0.0;                        // time constant of learning the resistance, > 0

  // Finite, within the bounds above and SettingBounds' hand bounds (positions, speeds, force).
  bool isValid() const;
};

class ExploringHand {
 public:
  explicit ExploringHand(const ExploreSettings& settings) : settings_(settings) {}

  // The push (N, along x) over the next step of stepS at timeS, given the puck's position and
  // speed at its start; moves the participant's state on (turns, learning). Never allocates.
  double push(double timeS, double stepS, double positionMm, double speedMmPerS);

  // The speed the participant intends at timeS (mm/s, > 0) and where it is heading (+1, -1).
  double intendedSpeedMmPerS(double timeS) const;
  int direction() const { return direction_; }
  double expectedResistanceN() const { return expectedResistanceN_; }

 private:
  ExploreSettings settings_;
  int direction_ = 1;
  double expectedResistanceN_ = 0.0;
};

}  // namespace kf
