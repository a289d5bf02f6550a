// FrictionMouseIn: the puck's position and speed from a device slot, reconstructed at audio
// rate from its timestamped 125 Hz reports. The position is the device's (SlotTrajectory):
// every reader of a slot, whenever it started, reads the same trajectory.
// Inputs: device (slot index), origin (mm, subtracted from x in double), interpolation
// (0 hold, 1 linear as the paper, 2 predictive). Outputs: x mm, y mm, speedX, speedY mm/s.
#include <cmath>

#include "AudioClock.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"
#include "TrajectoryReconstructor.hpp"

namespace {

enum Input { kDevice, kOriginMm, kInterpolation };

class FrictionMouseIn : public SCUnit {
 public:
  FrictionMouseIn() {
    mCalcFunc = make_calc_function<FrictionMouseIn, &FrictionMouseIn::next>();
    // Not set_calc_function, which would run a block now: reports and frames are taken by the
    // first real block, at its own time.
    for (int c = 0; c < 4; ++c) out0(c) = 0.f;
  }

 private:
  void next(int numSamples) {
    const int index = kf::sc::slotIndexOf(in0(kDevice));
    const kf::sc::BlockClock clock = kf::sc::blockClockOf(mWorld);
    const kf::sc::SlotView slot = kf::sc::viewSlot(index, clock);
    if (slot.device == nullptr) {
      if (index < 0)
        mSlot.badIndex(mWorld, "FrictionMouseIn", in0(kDevice), kf::sc::kNumDeviceSlots, "position and speed are 0.");
      else
        mSlot.closed(mWorld, "FrictionMouseIn", index, "position and speed are 0.");
      for (int c = 0; c < 4; ++c) std::fill_n(out(c), numSamples, 0.f);
      return;
    }
    const kf::TrajectoryMode mode = kf::trajectoryModeFromCode(kf::sc::codeOf(in0(kInterpolation)));
    if (mSlot.isNew(slot.generation)) {
      // Joins the device where the puck is: the slot's reference for this mode already holds
      // this block's entries.
      mTrajectory = slot.trajectory->reference(mode);
    } else {
      kf::sc::addEntries(mTrajectory, slot.trajectory->entries(), slot.trajectory->numEntries());
      mTrajectory.setMode(mode);
    }
    const double originMm = usableOriginMm();
    if (mCalcRate == calc_FullRate) {
      // The slot's own sample duration, so all readers compute the same times.
      mTrajectory.render(clock.startS, clock.sampleDurS, numSamples, originMm, out(0), out(1), out(2), out(3));
    } else {
      // Control rate: the block is rendered at audio rate as every reader renders it, and the
      // output is its last sample, so kr and ar readers of a slot agree whenever they started.
      mTrajectory.render(clock.startS, clock.sampleDurS, clock.numSamples, originMm, nullptr, nullptr, nullptr,
                         nullptr);
      out0(0) = static_cast<float>(mTrajectory.renderedXMm() - originMm);
      out0(1) = static_cast<float>(mTrajectory.renderedYMm());
      out0(2) = static_cast<float>(mTrajectory.renderedSpeedXMmPerS());
      out0(3) = static_cast<float>(mTrajectory.renderedSpeedYMmPerS());
    }
  }

  // A NaN or infinite origin would make every position NaN: the last finite origin is kept (as
  // SpatialBufRd does), 0 while there has been none, said once per unit.
  double usableOriginMm() {
    const float value = in0(kOriginMm);
    if (std::isfinite(value)) return mGoodOriginMm = value;
    if (mBadOrigin.first(0))
      kf::sc::postFromRt(mWorld,
                         "FrictionMouseIn: origin %g is not finite; the last finite origin is kept (0 before the "
                         "first).\n",
                         kf::sc::shownValue(value));
    return mGoodOriginMm;
  }

  kf::TrajectoryReconstructor mTrajectory;
  kf::sc::SlotFollower mSlot;
  kf::sc::FirstTimeOnly mBadOrigin;
  double mGoodOriginMm = 0.0;  // the last finite origin, 0 before the first
};

}  // namespace

// Registered as a unit whose wire buffers must not alias (kUnitDef_CantAliasInputsToOutputs).
// supernova otherwise gives an output that no unit reads (y, in a 1D graph) a wire buffer that is
// free again at this very unit, and hands the same buffer to the next output (speedX): render()
// writes y after speedX, so speedX read 0 throughout (measured: [m[0], m[2]] read 0 mm/s under
// supernova, 105 mm/s under scsynth, whose unread outputs keep a buffer of their own). With the
// flag, supernova reuses only buffers whose last reader came before this unit. In scsynth the
// flag only keeps the (rare) audio-rate inputs apart from the outputs.
void registerFrictionMouseIn() { registerUnit<FrictionMouseIn>(ft, "FrictionMouseIn", true); }
