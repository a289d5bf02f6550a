// LoudnessToFriction: the paper's equations (1) and (2), audio in, force in N out.
// Inputs: in, window (s), loDb, hiDb, loForce (N), hiForce (N), ref, maxWindow (s, fixed at
// init). Everything but `in` is read once per block.
// Bad inputs give a defined output and one message each, the first time (help: "Bad inputs"):
// maxWindow NaN/0/negative is the paper's, beyond the history limit (inf too) the limit; window
// NaN/0/negative is the paper's, beyond maxWindow (inf too) maxWindow; the mapping's fallbacks
// are kf::usableMapping's. A failed history allocation leaves the force of silence (loForce).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>

#include "LoudnessToFriction.hpp"
#include "PluginShared.hpp"

namespace {

enum Input { kIn, kWindowS, kLoDb, kHiDb, kLoForceN, kHiForceN, kRef, kMaxWindowS };

// The kinds of bad input, each posted once per unit (FirstTimeOnly).
enum BadInput { kBadWindow, kWindowBeyondMax, kBadLoDb, kBadHiDb, kBadLoForce, kBadHiForce, kBadRef };

// Upper bound on the history, whatever maxWindow asks: 2^22 samples is 21 s at 192 kHz.
constexpr int kMaxHistorySamples = 1 << 22;

class LoudnessToFrictionUGen : public SCUnit {
 public:
  LoudnessToFrictionUGen() {
    mCapacity = historySamples();
    mHistory = static_cast<float*>(RTAlloc(mWorld, sizeof(float) * mCapacity + kHistoryAlign));
    if (mHistory == nullptr) {
      // Not 0 N, which no device can give: the force of silence, following the mapping inputs.
      kf::sc::postFromRt(mWorld,
                         "LoudnessToFriction: RT memory allocation failed (%d kB for maxWindow %g s); the output "
                         "stays at the force of silence (loForce). Raise ServerOptions.memSize.\n",
                         static_cast<int>(sizeof(float) * mCapacity / 1024), mMaxWindowS);
      mCore.emplace(&mSilence, 1);
      mCalcFunc = make_calc_function<LoudnessToFrictionUGen, &LoudnessToFrictionUGen::nextWithoutHistory>();
      nextWithoutHistory(1);
      return;
    }
    mCore.emplace(alignedHistory(), mCapacity);
    mCalcFunc = make_calc_function<LoudnessToFrictionUGen, &LoudnessToFrictionUGen::next>();
    updateWindow();
    updateMapping();
    out0(0) = mCore->peekForce(in0(kIn));  // initial value, without consuming the first sample
  }

  ~LoudnessToFrictionUGen() {
    if (mHistory != nullptr) RTFree(mWorld, mHistory);
  }

 private:
  void next(int numSamples) {
    updateWindow();
    updateMapping();
    mCore->process(in(kIn), out(0), numSamples);
  }

  // The history could not be allocated: the core runs on one silent sample it never takes in.
  void nextWithoutHistory(int numSamples) {
    updateMapping();
    std::fill_n(out(0), numSamples, mCore->peekForce(0.f));
  }

  // The history's length from maxWindow, and mMaxWindowS: NaN, 0 and negative are the paper's
  // maxWindow; beyond kMaxHistorySamples (inf too) the limit. Read once, at init.
  int historySamples() {
    mMaxWindowS = in0(kMaxWindowS);
    if (!(mMaxWindowS > 0.0)) {
      kf::sc::postFromRt(mWorld, "LoudnessToFriction: maxWindow %g s is not > 0; the paper's %g s used.\n",
                         kf::sc::shownValue(mMaxWindowS), kf::paper::mapping::maxWindowS);
      mMaxWindowS = kf::paper::mapping::maxWindowS;
    }
    const double wanted = std::ceil(sampleRate() * mMaxWindowS);
    if (wanted > kMaxHistorySamples) {
      const double limitS = kMaxHistorySamples / sampleRate();
      kf::sc::postFromRt(mWorld,
                         "LoudnessToFriction: maxWindow %g s is beyond the history limit of %d samples; %g s used.\n",
                         mMaxWindowS, kMaxHistorySamples, limitS);
      mMaxWindowS = limitS;
      return kMaxHistorySamples;
    }
    return std::max(1, static_cast<int>(wanted));
  }

  // window NaN, 0 or negative: the paper's window (at most maxWindow); beyond maxWindow (inf
  // too): maxWindow. A window below half a sample is one sample.
  void updateWindow() {
    const float rawWindowS = in0(kWindowS);
    if (mWindowSet && std::memcmp(&rawWindowS, &mRawWindowS, sizeof(float)) == 0) return;  // as updateMapping
    mWindowSet = true;
    mRawWindowS = rawWindowS;
    double windowS = rawWindowS;
    if (!(windowS > 0.0)) {
      if (mBadInputs.first(kBadWindow))
        kf::sc::postFromRt(mWorld, "LoudnessToFriction: window %g s is not > 0; the paper's %g s used.\n",
                           kf::sc::shownValue(windowS), kf::paper::mapping::windowS);
      windowS = std::min(kf::paper::mapping::windowS, mMaxWindowS);
    } else if (windowS > mMaxWindowS) {
      if (mBadInputs.first(kWindowBeyondMax))
        kf::sc::postFromRt(mWorld, "LoudnessToFriction: window %g s is beyond maxWindow %g s; maxWindow used.\n",
                           windowS, mMaxWindowS);
      windowS = mMaxWindowS;
    }
    mCore->setWindowSamples(kf::windowSamples(sampleRate(), windowS, mCapacity));
  }

  void updateMapping() {
    // The five inputs compared as bits (a NaN held is the same NaN): the usual block ends here.
    const float raw[5] = {in0(kLoDb), in0(kHiDb), in0(kLoForceN), in0(kHiForceN), in0(kRef)};
    if (mMapped && std::memcmp(raw, mRawMapping, sizeof(raw)) == 0) return;  // a few pow()s: only on a change
    mMapped = true;
    std::memcpy(mRawMapping, raw, sizeof(raw));
    const kf::FrictionMapping wanted{raw[0], raw[1], raw[2], raw[3], raw[4]};
    const kf::FrictionMapping used = kf::usableMapping(wanted);
    noticeReplaced(kBadLoDb, "loDb", wanted.loDb, used.loDb, " dB", "a finite level");
    noticeReplaced(kBadHiDb, "hiDb", wanted.hiDb, used.hiDb, " dB", "a finite level");
    noticeReplaced(kBadLoForce, "loForce", wanted.loForceN, used.loForceN, " N", "a finite force >= 0");
    noticeReplaced(kBadHiForce, "hiForce", wanted.hiForceN, used.hiForceN, " N", "a finite force >= 0");
    noticeReplaced(kBadRef, "ref", wanted.ref, used.ref, "", "a finite amplitude > 0");
    mCore->setMapping(used);
  }

  void noticeReplaced(BadInput kind, const char* name, double wanted, double used, const char* unit, const char* rule) {
    if (wanted == used || !mBadInputs.first(kind)) return;
    kf::sc::postFromRt(mWorld, "LoudnessToFriction: %s %g%s is not %s; %g%s used.\n", name, kf::sc::shownValue(wanted),
                       unit, rule, used, unit);
  }

  // The ring starts on a cache line (the pool's blocks need not): the core's eight-wide loads
  // and stores then never straddle two lines (8 % faster in a 400-instance test of the core).
  static constexpr size_t kHistoryAlign = 64;
  float* alignedHistory() const {
    const auto at = reinterpret_cast<uintptr_t>(mHistory);
    return reinterpret_cast<float*>((at + kHistoryAlign - 1) & ~uintptr_t{kHistoryAlign - 1});
  }
  float* mHistory = nullptr;  // as RTAlloc gave it
  float mSilence = 0.f;       // the history of one sample when the allocation failed
  int mCapacity = 1;
  double mMaxWindowS = 0.0;  // maxWindow as used (the input, the paper's or the limit)
  // The core lives inside the unit, made once the history is allocated: no other allocation.
  std::optional<kf::LoudnessToFriction> mCore;
  // The inputs the mapping and the window were last made from.
  float mRawMapping[5] = {};
  bool mMapped = false;
  float mRawWindowS = 0.f;
  bool mWindowSet = false;
  kf::sc::FirstTimeOnly mBadInputs;
};

}  // namespace

void registerLoudnessToFriction() { registerUnit<LoudnessToFrictionUGen>(ft, "LoudnessToFriction"); }
