// FrictionButtons: the puck's buttons from a device slot, one output per button (left, right,
// middle): 1 while it is down, else 0. Per block, a button down in any of the block's reports
// reads 1 (SlotTrajectory::buttons), so a click shorter than a block is not lost.
// Input: device (slot index).
#include <algorithm>

#include "AudioClock.hpp"
#include "DeviceSlots.hpp"
#include "PluginShared.hpp"

namespace {

constexpr int kNumButtons = 3;

class FrictionButtons : public SCUnit {
 public:
  FrictionButtons() {
    mCalcFunc = make_calc_function<FrictionButtons, &FrictionButtons::next>();
    // As FrictionMouseIn: the first real block takes the reports, at its own time.
    for (int c = 0; c < kNumButtons; ++c) out0(c) = 0.f;
  }

 private:
  void next(int numSamples) {
    const int index = kf::sc::slotIndexOf(in0(0));
    const kf::sc::SlotView slot = kf::sc::viewSlot(index, kf::sc::blockClockOf(mWorld));
    uint32_t buttons = 0;
    if (slot.device == nullptr) {
      if (index < 0)
        mSlot.badIndex(mWorld, "FrictionButtons", in0(0), kf::sc::kNumDeviceSlots, "the buttons read 0.");
      else
        mSlot.closed(mWorld, "FrictionButtons", index, "the buttons read 0.");
    } else {
      mSlot.isNew(slot.generation);
      buttons = slot.trajectory->buttons();
    }
    for (int c = 0; c < kNumButtons; ++c) {
      const float down = (buttons >> c) & 1u ? 1.f : 0.f;
      if (mCalcRate == calc_FullRate)
        std::fill_n(out(c), numSamples, down);
      else
        out0(c) = down;
    }
  }

  kf::sc::SlotFollower mSlot;
};

}  // namespace

void registerFrictionButtons() { registerUnit<FrictionButtons>(ft, "FrictionButtons"); }
