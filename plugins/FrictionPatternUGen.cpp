// FrictionPattern: a spatial friction pattern (dsp/patterns/FrictionPatternCore), position (mm) in, force
// (N) out. Inputs: kind (fixed at init), position, loForce (N), hiForce (N), antialias (0/1),
// p1, p2, p3 (by kind, dsp/patterns/FrictionPatternCore.hpp); for kind slope p1 is the height signal; the
// 2D kinds (bumps2D, texture2D) read y (mm) as position is (0 for the others); then the force frame
// period (s, fixed at init: the device's, 1 ms by default; absent in SynthDefs of earlier versions).
// Position and height are read at audio rate as they are; at control rate they are interpolated
// linearly across the block from the last block's value (as SC UGens do), since a value held per
// block would make the travel, and every speed-based pattern, jump at block rate. Everything else
// is read once per block. Bad inputs (help: "Bad inputs"): a
// NaN/inf position holds the last finite one; a parameter out of its range keeps the last good
// value (the pattern's default before the first); loForce/hiForce not finite are the paper
// mapping's loForce/hiForce, negative 0 N; an unknown kind is a grating. Each posted once.
#include <algorithm>
#include <cmath>
#include <optional>

#include "PluginShared.hpp"
#include "patterns/FrictionPatternCore.hpp"

namespace {

using kf::patterns::PatternKind;

enum Input { kKind, kPositionMm, kLoForceN, kHiForceN, kAntialias, kP1, kP2, kP3, kYMm, kFramePeriodS };

// The kinds of bad input, each posted once per unit (FirstTimeOnly).
enum BadInput { kBadKind, kBadLoForce, kBadHiForce, kBadP1, kBadP2, kBadP3 };

// What each kind's parameters are called and must be: positive (finite, > 0), finite, or unused.
enum class Rule { Unused, Positive, NonNegative, Finite };
struct KindInfo {
  const char* name;
  const char* params[3];
  Rule rules[3];
};
constexpr KindInfo kKinds[kf::patterns::kPatternKinds] = {
    {"grating", {"period", "duty", "edge"}, {Rule::Positive, Rule::Finite, Rule::Finite}},
    {"bumps", {"period", "width", "valleys"}, {Rule::Positive, Rule::Positive, Rule::Finite}},
    {"detents", {"spacing", "crest", ""}, {Rule::Positive, Rule::Finite, Rule::Unused}},
    {"texture", {"lo", "hi", "seed"}, {Rule::Positive, Rule::Positive, Rule::Finite}},
    {"viscous", {"fullSpeed", "", ""}, {Rule::Positive, Rule::Unused, Rule::Unused}},
    {"stickSlip", {"slipSpeed", "stickSpeed", ""}, {Rule::NonNegative, Rule::NonNegative, Rule::Unused}},
    {"slope", {"height", "fullSlope", ""}, {Rule::Unused, Rule::Positive, Rule::Unused}},
    {"bumps2D", {"spacingX", "spacingY", "width"}, {Rule::Positive, Rule::Positive, Rule::Positive}},
    {"texture2D", {"lo", "hi", "seed"}, {Rule::Positive, Rule::Positive, Rule::Finite}},
};

bool follows(Rule rule, float value) {
  switch (rule) {
    case Rule::Unused:
      return true;
    case Rule::Positive:
      return value > 0.f && std::isfinite(value);
    case Rule::NonNegative:
      return value >= 0.f && std::isfinite(value);
    case Rule::Finite:
      return std::isfinite(value);
  }
  return true;
}

class FrictionPatternUGen : public SCUnit {
 public:
  FrictionPatternUGen() {
    const int code = kf::sc::codeOf(in0(kKind));
    if (code < 0 || code >= kf::patterns::kPatternKinds) {
      kf::sc::postFromRt(mWorld, "FrictionPattern: kind %g is no pattern (0..%d); a grating is used.\n",
                         kf::sc::shownValue(in0(kKind)), kf::patterns::kPatternKinds - 1);
    }
    mKind = code >= 0 && code < kf::patterns::kPatternKinds ? code : 0;
    // The force frame the pattern is made for (its travel and band limit), fixed at init: the
    // device's forceFramePeriodS; without the input (a SynthDef of an earlier version) the paper's.
    double framePeriodS = kf::paper::device::forceFramePeriodS;
    if (numInputs() > kFramePeriodS) {
      const double wanted = in0(kFramePeriodS);
      if (wanted >= 1e-4 && wanted <= 0.1)
        framePeriodS = wanted;
      else
        kf::sc::postFromRt(mWorld, "FrictionPattern: forceFramePeriod %g is not 0.0001 to 0.1 s; %g is used.\n",
                           kf::sc::shownValue(in0(kFramePeriodS)), framePeriodS);
    }
    mCore.emplace(static_cast<PatternKind>(mKind), sampleRate(), framePeriodS);
    mLastPositionMm = in0(kPositionMm);
    // The second signal beside the position: slope's height, the 2D kinds' y; none otherwise.
    if (mKind == static_cast<int>(PatternKind::Slope)) mSecond = kP1;
    if (kf::patterns::isTwoD(static_cast<PatternKind>(mKind)) && numInputs() > kYMm) mSecond = kYMm;
    mLastHeight = mSecond >= 0 ? in0(mSecond) : 0.f;
    mCalcFunc = make_calc_function<FrictionPatternUGen, &FrictionPatternUGen::next>();
    updateRange();
    // The initial value, before the first block: the minimum force (no travel yet).
    out0(0) = static_cast<float>(mRange.loN);
  }

 private:
  void next(int numSamples) {
    updateRange();
    checkParameters();
    mCore->setAntialias(in0(kAntialias) > 0.5f);
    const bool slope = mSecond >= 0;  // a second signal is read (slope's height, the 2D kinds' y)
    const bool positionAudio = isAudioRateIn(kPositionMm), heightAudio = !slope || isAudioRateIn(mSecond);
    const float positionNow = in0(kPositionMm), heightNow = slope ? in0(mSecond) : 0.f;
    // The anchor of a phase-continuous period change: the block's first position.
    mCore->setParameters(in0(kP1), in0(kP2), in0(kP3),
                         positionAudio ? in(kPositionMm)[0] : ramp(mLastPositionMm, positionNow, 1, numSamples));
    if (positionAudio && heightAudio) {
      mCore->process(in(kPositionMm), 1, slope ? in(mSecond) : nullptr, 1, out(0), numSamples);
    } else {
      // In chunks through small arrays on the stack: nothing allocated.
      float positions[kChunk], heights[kChunk];
      for (int start = 0; start < numSamples; start += kChunk) {
        const int n = std::min(kChunk, numSamples - start);
        for (int i = 0; i < n; ++i) {
          const int at = start + i;
          positions[i] = positionAudio ? in(kPositionMm)[at] : ramp(mLastPositionMm, positionNow, at + 1, numSamples);
          if (slope) heights[i] = heightAudio ? in(mSecond)[at] : ramp(mLastHeight, heightNow, at + 1, numSamples);
        }
        mCore->process(positions, 1, slope ? heights : nullptr, 1, out(0) + start, n);
      }
    }
    mLastPositionMm = positionNow;
    mLastHeight = heightNow;
  }

  // Sample k (1..n) of a block's line from the last block's value to this one's.
  static float ramp(float from, float to, int k, int n) {
    return static_cast<float>(from + (static_cast<double>(to) - from) * k / n);
  }

  void updateRange() {
    const float loN = in0(kLoForceN), hiN = in0(kHiForceN);
    mRange = kf::patterns::usableForceRange(loN, hiN);
    if (!(loN >= 0.f && std::isfinite(loN)) && mBadInputs.first(kBadLoForce))
      kf::sc::postFromRt(mWorld, "FrictionPattern: loForce %g N is not a finite force >= 0; %g N used.\n",
                         kf::sc::shownValue(loN), mRange.loN);
    if (!(hiN >= 0.f && std::isfinite(hiN)) && mBadInputs.first(kBadHiForce))
      kf::sc::postFromRt(mWorld, "FrictionPattern: hiForce %g N is not a finite force >= 0; %g N used.\n",
                         kf::sc::shownValue(hiN), mRange.hiN);
    mCore->setForceRange(mRange);
  }

  // The cores keep the last good value of a bad parameter; this says so, once per parameter.
  void checkParameters() {
    const KindInfo& info = kKinds[mKind];
    for (int p = 0; p < 3; ++p) {
      const float value = in0(kP1 + p);
      if (follows(info.rules[p], value) || !mBadInputs.first(kBadP1 + p)) continue;
      kf::sc::postFromRt(mWorld,
                         "FrictionPattern.%s: %s %g is not %s; the last good value is kept (the default before the "
                         "first).\n",
                         info.name, info.params[p], kf::sc::shownValue(value),
                         info.rules[p] == Rule::Finite
                             ? "finite"
                             : (info.rules[p] == Rule::Positive ? "a finite number > 0" : "a finite number >= 0"));
    }
  }

  static constexpr int kChunk = 64;
  int mKind = 0;
  int mSecond = -1;                                        // the input of the signal read beside the position, -1: none
  float mLastPositionMm = 0.f, mLastHeight = 0.f;          // control-rate values of the last block
  std::optional<kf::patterns::FrictionPatternCore> mCore;  // inside the unit: no allocation
  kf::patterns::ForceRange mRange;
  kf::sc::FirstTimeOnly mBadInputs;
};

}  // namespace

void registerFrictionPattern() { registerUnit<FrictionPatternUGen>(ft, "FrictionPattern"); }
