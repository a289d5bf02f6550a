// SpeedGovernor: friction (N) rising above a target speed (dsp/SpeedGovernor.hpp).
// Inputs: speedX, speedY (mm/s, FrictionMouseIn's outputs 2 and 3), target (mm/s), gain (N per
// mm/s), loForce, hiForce (N). All but the speeds are read once per block. A bad target or gain
// (NaN, inf, negative) or force (NaN, inf) keeps the last good value (target 0, gain 0, forces 0
// before the first), said once; hiForce below loForce is taken as loForce.
#include <algorithm>
#include <cmath>

#include "PluginShared.hpp"
#include "SpeedGovernor.hpp"

namespace {

enum Input { kSpeedX, kSpeedY, kTarget, kGain, kLoForce, kHiForce };

class SpeedGovernor : public SCUnit {
 public:
  SpeedGovernor() { set_calc_function<SpeedGovernor, &SpeedGovernor::next>(); }

 private:
  void next(int numSamples) {
    kf::GovernorSettings g;
    g.targetMmPerS = usable(kTarget, true, mTargetMmPerS, "target");
    g.gainNPerMmPerS = usable(kGain, true, mGainNPerMmPerS, "gain");
    g.loForceN = usable(kLoForce, false, mLoForceN, "loForce");
    g.hiForceN = std::max(usable(kHiForce, false, mHiForceN, "hiForce"), g.loForceN);
    kf::governorBlock(in(kSpeedX), isAudioRateIn(kSpeedX) ? 1 : 0, in(kSpeedY), isAudioRateIn(kSpeedY) ? 1 : 0, g,
                      out(0), numSamples);
  }

  // The input if it is finite (and >= 0 where nonNegative), else the last good value, said once.
  double usable(int input, bool nonNegative, double& good, const char* name) {
    const float value = in0(input);
    if (std::isfinite(value) && (!nonNegative || value >= 0.f)) return good = value;
    if (mBadInputs.first(input))
      kf::sc::postFromRt(mWorld, "SpeedGovernor: %s %g is not a finite number%s; the last good value is kept.\n", name,
                         kf::sc::shownValue(value), nonNegative ? " >= 0" : "");
    return good;
  }

  kf::sc::FirstTimeOnly mBadInputs;
  double mTargetMmPerS = 0.0, mGainNPerMmPerS = 0.0, mLoForceN = 0.0, mHiForceN = 0.0;
};

}  // namespace

void registerSpeedGovernor() { registerUnit<SpeedGovernor>(ft, "SpeedGovernor"); }
