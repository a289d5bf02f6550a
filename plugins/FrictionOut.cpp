// FrictionOut: sends an audio-rate force (N) to a device slot as 1 ms frames, each the mean
// over its millisecond, clamped to the device's range, NaN/Inf as the minimum. All FrictionOut
// of a slot are combined into one force (SlotForce: the forces above the minimum add up), so
// the device gets one frame per millisecond however many write to it. Outputs the force the
// device actually commanded after its safety path (slew, drive limits, watchdog), so it can be
// scoped and recorded: per sample for the last writer of a block (the only one when there is
// one), held from the previous block for the others.
// Inputs: device (slot index), force (N), fade (0..1, optional: 1 when absent), the weight of
// this writer's force above the minimum (by default its synth's gate envelope, FrictionOut.sc).
#include "AudioClock.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"

namespace {

enum Input { kDevice, kForceN, kFade };

constexpr float kFullWeight = 1.0f;  // the fade of a writer without that input

// Pushes the slot's frames to its device, each stamped with the device-clock time its
// millisecond ended: now, less the audio time between the frame's end and the end of the
// block being computed. Returns what the device commanded: in lockstep this frame's result,
// in realtime the latest sent to the magnet.
struct FrameSink {
  kf::Device* device;
  double deviceNowS;
  double blockEndS;
  float operator()(double frameTimeS, float forceN, double frameEndS) const {
    // Lockstep devices take frames on their own time (audio time less their origin).
    const double deviceFrameS = device->isLockstep() ? frameTimeS - device->lockstepOriginS() : frameTimeS;
    device->pushForceFrame(kf::ForceFrame{deviceFrameS, forceN, deviceNowS - (blockEndS - frameEndS)});
    return device->commandedForceN();
  }
};

class FrictionOut : public SCUnit {
 public:
  FrictionOut() {
    // Not set_calc_function, which would run a block now and send a frame at the wrong time.
    mCalcFunc = make_calc_function<FrictionOut, &FrictionOut::next>();
    follow(kf::sc::slotIndexOf(in0(kDevice)));
    out0(0) = mMinForceN;
  }

  ~FrictionOut() {
    kf::sc::SlotForce* force = kf::sc::forceOfSlot(mIndex);
    if (force == nullptr) return;
    force->unregisterWriter();
    // The others of this block may all have written already: then the block is framed now.
    const kf::sc::BlockClock clock = kf::sc::blockClockOf(mWorld);
    kf::Device* device = kf::sc::deviceOfSlot(mIndex, clock.startS + kf::sc::blockDurationS(mWorld), nullptr);
    if (device == nullptr) return;
    FrameSink sink{device, device->nowS(), clock.startS + kf::sc::blockDurationS(mWorld)};
    force->writerGone(clock, sink);
    // The last writer gone (its synth freed, Cmd-., s.freeAll, the server quitting): the magnet
    // goes off at the device's next pump, not after the watchdog's 10 ms.
    if (force->registeredWriters() == 0) device->requestOff();
  }

 private:
  void next(int numSamples) {
    if (mOrphaned) {
      std::fill_n(out(0), numSamples, mMinForceN);
      return;
    }
    const int index = kf::sc::slotIndexOf(in0(kDevice));
    if (index != mIndex) {
      follow(index);
      mSawDevice = false;  // another slot: it follows that slot's device from now on
    }
    const kf::sc::BlockClock clock = kf::sc::blockClockOf(mWorld);
    const double blockEndS = clock.startS + kf::sc::blockDurationS(mWorld);
    uint32_t generation = 0;
    kf::Device* device = kf::sc::deviceOfSlot(index, blockEndS, &generation);
    kf::sc::SlotForce* force = kf::sc::forceOfSlot(index);
    if (device == nullptr || force == nullptr) {
      if (index < 0)
        mSlot.badIndex(mWorld, "FrictionOut", in0(kDevice), kf::sc::kNumDeviceSlots, "no force is sent.");
      else
        mSlot.closed(mWorld, "FrictionOut", index, "no force is sent.");
      std::fill_n(out(0), numSamples, mMinForceN);  // no device: its magnet is off
      return;
    }
    if (mSlot.isNew(generation)) mMinForceN = static_cast<float>(device->spec().minForceN);
    // Written for the device it first saw in its slot: once that one is closed, this writer
    // never acts on the next device opened there (a forgotten synth would hold its puck).
    const uint32_t closes = kf::sc::closesOfSlot(index);
    if (!mSawDevice) {
      mSawDevice = true;
      mClosesAtFirstDevice = closes;
    } else if (closes != mClosesAtFirstDevice) {
      kf::sc::postFromRt(mWorld,
                         "FrictionOut: the device it wrote to in slot %d was closed; it sends no force to the next "
                         "one there (free its synth)\n",
                         index);
      follow(-1);  // no longer one of the slot's writers, whose frames would wait for it
      mOrphaned = true;
      std::fill_n(out(0), numSamples, mMinForceN);
      return;
    }

    FrameSink sink{device, device->nowS(), blockEndS};
    // A control-rate force is held over the block.
    const bool audioRate = isAudioRateIn(kForceN);
    // The fade likewise; a SynthDef built before it had the input (two inputs) weighs 1.
    const bool hasFade = numInputs() > kFade;
    const float* fade = hasFade ? in(kFade) : &kFullWeight;
    const int fadeSamples = hasFade && isAudioRateIn(kFade) ? clock.numSamples : 1;
    const bool framed = force->write(clock, in(kForceN), audioRate ? clock.numSamples : 1, fade, fadeSamples, sink);
    if (framed && mCalcRate == calc_FullRate) {
      std::copy_n(force->commanded(), std::min(numSamples, kf::sc::SlotForce::kMaxBlockSamples), out(0));
    } else if (framed) {
      out0(0) = force->commanded()[clock.numSamples - 1];
    } else {
      std::fill_n(out(0), numSamples, force->lastCommandedN());
    }
    // Our share of the audio thread (a lockstep device's clock is audio time: nothing to time).
    if (!device->isLockstep()) device->noteAudioCall(device->nowS() - sink.deviceNowS);
  }

  // Registers this writer with a slot (moving from the previous one), so that the slot knows
  // when a block has all its writers.
  void follow(int index) {
    if (kf::sc::SlotForce* previous = kf::sc::forceOfSlot(mIndex)) previous->unregisterWriter();
    mIndex = index;
    if (kf::sc::SlotForce* force = kf::sc::forceOfSlot(mIndex)) force->registerWriter();
  }

  int mIndex = -1;
  bool mSawDevice = false;                                            // a device was open in its slot while it ran
  uint32_t mClosesAtFirstDevice = 0;                                  // closesOfSlot when it first saw one
  bool mOrphaned = false;                                             // that device was closed: it writes no more
  float mMinForceN = static_cast<float>(kf::DeviceSpec{}.minForceN);  // of the last device seen
  kf::sc::SlotFollower mSlot;
};

}  // namespace

void registerFrictionOut() { registerUnit<FrictionOut>(ft, "FrictionOut"); }
