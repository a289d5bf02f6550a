// FrictionOut: sends an audio-rate force (N) to a device slot as 1 ms frames, each the mean
// over its millisecond, clamped to the device's range, NaN/Inf as the minimum. Outputs the
// force the device actually commanded after its safety path, so it can be scoped and recorded.
// Inputs: device (slot index), force (N).
#include <new>

#include "AudioClock.hpp"
#include "DeviceSlots.hpp"
#include "ForceFramer.hpp"
#include "PluginShared.hpp"

namespace {

enum Input { kDevice, kForceN };

class FrictionOut : public SCUnit {
 public:
  FrictionOut() {
    // Not set_calc_function, which would run a block now and send a frame at the wrong time.
    mCalcFunc = make_calc_function<FrictionOut, &FrictionOut::next>();
    out0(0) = mMinForceN;
  }

 private:
  void next(int numSamples) {
    const int index = kf::sc::slotIndexOf(in0(kDevice));
    const double startS = kf::sc::blockStartTimeS(mWorld);
    uint32_t generation = 0;
    kf::Device* device = kf::sc::deviceOfSlot(index, startS + kf::sc::blockDurationS(mWorld), &generation);
    if (device == nullptr) {
      if (index < 0)
        mSlot.badIndex(mWorld, "FrictionOut", in0(kDevice), kf::sc::kNumDeviceSlots, "no force is sent.");
      else
        mSlot.closed(mWorld, "FrictionOut", index, "no force is sent.");
      std::fill_n(out(0), numSamples, mMinForceN);  // no device: its magnet is off
      return;
    }
    if (mSlot.isNew(generation)) attach(*device);

    // Each frame is stamped with the device-clock time its millisecond ended: now, less the
    // audio time between the frame's end and the end of this block.
    const double blockEndS = startS + numSamples / sampleRate();
    const double deviceNowS = device->nowS();
    const double framePeriodS = device->spec().forceFramePeriodS;
    auto sink = [&](double frameTimeS, float forceN) {
      // Lockstep devices take frames on their own time (audio time less their origin).
      const double deviceFrameS = device->isLockstep() ? frameTimeS - device->lockstepOriginS() : frameTimeS;
      device->pushForceFrame(
          kf::ForceFrame{deviceFrameS, forceN, deviceNowS - (blockEndS - (frameTimeS + framePeriodS))});
      // The output shows what the device commanded after its safety path (slew, drive limits,
      // watchdog): in lockstep this frame's result, in realtime the latest sent to the magnet.
      mFramer.showCommanded(device->commandedForceN());
    };
    const double sampleDurS = 1.0 / sampleRate();
    if (isAudioRateIn(kForceN)) {
      mFramer.process(startS, sampleDurS, in(kForceN), numSamples, out(0), sink);
    } else {
      // A control-rate force is held over the block.
      const float heldN = in0(kForceN);
      for (int i = 0; i < numSamples; ++i)
        mFramer.process(startS + i * sampleDurS, sampleDurS, &heldN, 1, out(0) + i, sink);
    }
  }

  void attach(const kf::Device& device) {
    const kf::DeviceSpec& spec = device.spec();
    mMinForceN = static_cast<float>(spec.minForceN);
    mFramer.~ForceFramer();
    new (&mFramer) kf::ForceFramer(spec.forceFramePeriodS, spec.minForceN, spec.maxForceN);
  }

  kf::ForceFramer mFramer;
  float mMinForceN = static_cast<float>(kf::DeviceSpec{}.minForceN);  // of the last device seen
  kf::sc::SlotFollower mSlot;
};

}  // namespace

void registerFrictionOut() { registerUnit<FrictionOut>(ft, "FrictionOut"); }
