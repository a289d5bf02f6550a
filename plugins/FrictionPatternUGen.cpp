// FrictionPattern: a spatial friction pattern (dsp/FrictionPatternCore), position (mm) in, force
// (N) out. Inputs: kind (fixed at init), position, minForce (N), maxForce (N), antialias (0/1),
// p1, p2, p3 (by kind, dsp/FrictionPatternCore.hpp); for kind slope p1 is the height signal,
// read at its rate. Everything else is read once per block. Bad inputs (help: "Bad inputs"): a
// NaN/inf position holds the last finite one; a parameter out of its range keeps the last good
// value (the pattern's default before the first); minForce/maxForce not finite are the paper
// mapping's loForce/hiForce, negative 0 N; an unknown kind is a grating. Each posted once.
#include <cmath>
#include <optional>

#include "FrictionPatternCore.hpp"
#include "PluginShared.hpp"

namespace {

using kf::patterns::PatternKind;

enum Input { kKind, kPositionMm, kMinForceN, kMaxForceN, kAntialias, kP1, kP2, kP3 };

// The kinds of bad input, each posted once per unit (FirstTimeOnly).
enum BadInput { kBadKind, kBadMinForce, kBadMaxForce, kBadP1, kBadP2, kBadP3 };

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
    mCore.emplace(static_cast<PatternKind>(mKind), sampleRate());
    mCalcFunc = make_calc_function<FrictionPatternUGen, &FrictionPatternUGen::next>();
    updateRange();
    // The initial value, before the first block: the minimum force (no travel yet).
    out0(0) = static_cast<float>(mRange.minN);
  }

 private:
  void next(int numSamples) {
    updateRange();
    checkParameters();
    mCore->setAntialias(in0(kAntialias) > 0.5f);
    mCore->setParameters(in0(kP1), in0(kP2), in0(kP3), in(kPositionMm)[0]);
    const bool slope = mKind == static_cast<int>(PatternKind::Slope);
    mCore->process(in(kPositionMm), isAudioRateIn(kPositionMm) ? 1 : 0, slope ? in(kP1) : nullptr,
                   isAudioRateIn(kP1) ? 1 : 0, out(0), numSamples);
  }

  void updateRange() {
    const float minN = in0(kMinForceN), maxN = in0(kMaxForceN);
    mRange = kf::patterns::usableForceRange(minN, maxN);
    if (!(minN >= 0.f && std::isfinite(minN)) && mBadInputs.first(kBadMinForce))
      kf::sc::postFromRt(mWorld, "FrictionPattern: minForce %g N is not a finite force >= 0; %g N used.\n",
                         kf::sc::shownValue(minN), mRange.minN);
    if (!(maxN >= 0.f && std::isfinite(maxN)) && mBadInputs.first(kBadMaxForce))
      kf::sc::postFromRt(mWorld, "FrictionPattern: maxForce %g N is not a finite force >= 0; %g N used.\n",
                         kf::sc::shownValue(maxN), mRange.maxN);
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

  int mKind = 0;
  std::optional<kf::patterns::FrictionPatternCore> mCore;  // inside the unit: no allocation
  kf::patterns::ForceRange mRange;
  kf::sc::FirstTimeOnly mBadInputs;
};

}  // namespace

void registerFrictionPattern() { registerUnit<FrictionPatternUGen>(ft, "FrictionPattern"); }
