// FrictionDrive: the drive signal of a DC-coupled audio output for a device slot's magnet
// (ARCHITECTURE.md, the audio drive): the slot's one force (every FrictionOut of it together)
// through the safety path and the drive calibration (kfDriveCalibrate), sample by sample, one
// block late. 0 while no calibration is loaded for the slot's device, no writer framed the
// previous block, or an exit signal came; 0 also from every FrictionDrive of the slot but the
// first to run in a block (a slot has one drive: two summed into one channel stay safe).
// Input: device (slot index). Output: sample values for Out.ar to the interface's channel.
#include "AudioClock.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"
#include "SlotDrive.hpp"

namespace {

enum Input { kDevice };

class FrictionDrive : public SCUnit {
 public:
  FrictionDrive() {
    mCalcFunc = make_calc_function<FrictionDrive, &FrictionDrive::next>();
    out0(0) = 0.0f;
  }

 private:
  void next(int numSamples) {
    const int index = kf::sc::slotIndexOf(in0(kDevice));
    const kf::sc::BlockClock clock = kf::sc::blockClockOf(mWorld);
    uint32_t generation = 0;
    kf::Device* device = kf::sc::deviceOfSlot(index, clock.startS + kf::sc::blockDurationS(mWorld), &generation);
    kf::sc::SlotForce* force = kf::sc::forceOfSlot(index);
    kf::sc::SlotDrive* drive = kf::sc::driveOfSlot(index);
    float* output = out(0);
    if (device == nullptr || force == nullptr || drive == nullptr) {
      if (index < 0)
        mSlot.badIndex(mWorld, "FrictionDrive", in0(kDevice), kf::sc::kNumDeviceSlots, "its output is 0.");
      else
        mSlot.closed(mWorld, "FrictionDrive", index, "its output is 0.");
      std::fill_n(output, numSamples, 0.0f);
      return;
    }
    mSlot.isNew(generation);
    bool another = false;
    const float* samples = drive->samples(clock, generation, *force, another);
    if (samples == nullptr) {  // another drive of the slot ran first, or no chain: 0, said once each
      // Halted (a /quit's unload, a signal: the blocks until the driver stops): 0, nothing to say.
      if (kf::sc::drivesHalted()) {
        std::fill_n(output, numSamples, 0.0f);
        return;
      }
      if (another && mNotes.first(kAnotherDrive))
        kf::sc::postFromRt(mWorld,
                           "FrictionDrive: the device at index %d has one drive, and another FrictionDrive of "
                           "it ran first in this block; this one's output is 0.\n",
                           index);
      else if (!another && mNotes.first(kNoChain))
        kf::sc::postFromRt(mWorld,
                           "FrictionDrive: no drive calibration is loaded for the device at index %d "
                           "(FrictionDevice.loadDrive); its output is 0.\n",
                           index);
      std::fill_n(output, numSamples, 0.0f);
      return;
    }
    const int n = std::min(numSamples, kf::sc::SlotDrive::kMaxBlockSamples);
    std::copy_n(samples, n, output);
    std::fill(output + n, output + numSamples, 0.0f);  // beyond the largest block: 0
  }

  kf::sc::SlotFollower mSlot;
  enum Note { kNoChain, kAnotherDrive };
  kf::sc::FirstTimeOnly mNotes;
};

}  // namespace

void registerFrictionDrive() { registerUnit<FrictionDrive>(ft, "FrictionDrive"); }
