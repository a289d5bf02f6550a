// FrictionMouseIn: the puck's position and speed from a device slot, reconstructed at audio
// rate from its timestamped 125 Hz reports.
// Inputs: device (slot index), origin (mm, subtracted from x in double), interpolation
// (0 hold, 1 linear as the paper, 2 predictive). Outputs: x mm, y mm, speedX, speedY mm/s.
#include <new>

#include "AudioClock.hpp"
#include "DeviceClockMapper.hpp"
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
    const int index = static_cast<int>(in0(kDevice));
    const double startS = kf::sc::blockStartTimeS(mWorld);
    const kf::sc::SlotView slot = kf::sc::viewSlot(index, mWorld->mBufCounter, startS + kf::sc::blockDurationS(mWorld));
    if (slot.device == nullptr) {
      mSlot.closed(mWorld, "FrictionMouseIn", index, "position and speed are 0.");
      for (int c = 0; c < 4; ++c) std::fill_n(out(c), numSamples, 0.f);
      return;
    }
    if (mSlot.isNew(slot.generation)) attach(*slot.device);

    const kf::DeviceSpec& spec = slot.device->spec();
    const bool lockstep = slot.device->isLockstep();
    const double originS = slot.device->lockstepOriginS();
    for (int i = 0; i < slot.numReports; ++i) {
      const kf::MouseReport& r = slot.reports[i];
      // Lockstep devices run on audio time; realtime ones on their own clock, mapped here.
      const double reportS = lockstep ? r.deviceTimeS + originS : mClock.map(r.deviceTimeS, startS);
      mTrajectory.addReport(reportS, r.dxCounts * spec.countMm, r.dyCounts * spec.countMm, r.flags, r.deviceTimeS);
    }
    mTrajectory.setMode(kf::trajectoryModeFromCode(static_cast<int>(in0(kInterpolation))));
    mTrajectory.render(startS, 1.0 / sampleRate(), numSamples, in0(kOriginMm), out(0), out(1), out(2), out(3));
  }

  // A new device in the slot: start from its origin, with its update rate.
  void attach(const kf::Device& device) {
    mTrajectory.~TrajectoryReconstructor();
    new (&mTrajectory) kf::TrajectoryReconstructor(device.spec().updateRateHz);
    mClock.reset();
  }

  kf::TrajectoryReconstructor mTrajectory;
  kf::DeviceClockMapper mClock;
  kf::sc::SlotFollower mSlot;
};

}  // namespace

void registerFrictionMouseIn() { registerUnit<FrictionMouseIn>(ft, "FrictionMouseIn"); }
