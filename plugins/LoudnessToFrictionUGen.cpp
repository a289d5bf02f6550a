// LoudnessToFriction: the paper's equations (1) and (2), audio in, force in N out.
// Inputs: in, window (s), loDb, hiDb, loForce (N), hiForce (N), ref, maxWindow (s, fixed at
// init). Everything but `in` is read once per block.
#include <algorithm>
#include <cmath>
#include <optional>

#include "LoudnessToFriction.hpp"
#include "PluginShared.hpp"

namespace {

enum Input { kIn, kWindowS, kLoDb, kHiDb, kLoForceN, kHiForceN, kRef, kMaxWindowS };

// Upper bound on the history, whatever maxWindow asks: 2^22 samples is 21 s at 192 kHz.
constexpr int kMaxHistorySamples = 1 << 22;

class LoudnessToFrictionUGen : public SCUnit {
 public:
  LoudnessToFrictionUGen() {
    const double maxWindowS = std::max<double>(in0(kMaxWindowS), in0(kWindowS));
    const double wanted = std::ceil(sampleRate() * (std::isfinite(maxWindowS) ? maxWindowS : 0.0));
    mCapacity = static_cast<int>(std::clamp(wanted, 1.0, double(kMaxHistorySamples)));
    mHistory = static_cast<float*>(RTAlloc(mWorld, sizeof(float) * mCapacity));
    if (mHistory == nullptr) {
      kf::sc::clearUnitOnAllocFailure(this, "LoudnessToFriction");
      return;
    }
    mCore.emplace(mHistory, mCapacity);
    mCalcFunc = make_calc_function<LoudnessToFrictionUGen, &LoudnessToFrictionUGen::next>();
    updateParameters();
    out0(0) = mCore->peekForce(in0(kIn));  // initial value, without consuming the first sample
  }

  ~LoudnessToFrictionUGen() {
    if (mHistory != nullptr) RTFree(mWorld, mHistory);
  }

 private:
  void next(int numSamples) {
    updateParameters();
    mCore->process(in(kIn), out(0), numSamples);
  }

  void updateParameters() {
    mCore->setWindowSamples(kf::windowSamples(sampleRate(), in0(kWindowS), mCapacity));
    const kf::FrictionMapping mapping{in0(kLoDb), in0(kHiDb), in0(kLoForceN), in0(kHiForceN), in0(kRef)};
    if (mapping.loDb != mMapping.loDb || mapping.hiDb != mMapping.hiDb || mapping.loForceN != mMapping.loForceN ||
        mapping.hiForceN != mMapping.hiForceN || mapping.ref != mMapping.ref) {
      mMapping = mapping;
      mCore->setMapping(mapping);  // a few pow()s: only when a parameter moved
    }
  }

  float* mHistory = nullptr;
  int mCapacity = 1;
  // The core lives inside the unit, made once the history is allocated: no other allocation.
  std::optional<kf::LoudnessToFriction> mCore;
  kf::FrictionMapping mMapping;
};

}  // namespace

void registerLoudnessToFriction() { registerUnit<LoudnessToFrictionUGen>(ft, "LoudnessToFriction"); }
