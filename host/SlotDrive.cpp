#include "SlotDrive.hpp"

#include <algorithm>
#include <atomic>
#include <limits>

#include "DeviceSlots.hpp"

namespace kf::sc {

namespace {

std::atomic<bool> gDrivesHalted{false};
SlotDrive gDrives[kNumDeviceSlots];
// NaN is the minimum force: the input for the samples of a block beyond those its writers framed
// (a block size change), so that process() always has a block of input.
float gNoForce[SlotDrive::kMaxBlockSamples];
const bool gNoForceFilled = [] {
  std::fill_n(gNoForce, SlotDrive::kMaxBlockSamples, std::numeric_limits<float>::quiet_NaN());
  return true;
}();

}  // namespace

SlotDrive::SlotDrive() = default;

AudioDrive* SlotDrive::publish(AudioDrive* drive, uint32_t generation) {
  AudioDrive* previous = drive_;
  const bool sameDevice = previous != nullptr && drive != nullptr && generation == generation_;
  if (sameDevice)
    drive->continueFrom(*previous);
  else
    computedBlock_ = -1;  // another device: its drive starts from the magnet off
  drive_ = drive;
  generation_ = generation;
  return previous;
}

const float* SlotDrive::samples(const BlockClock& clock, uint32_t generation, const SlotForce& force, bool& another) {
  another = false;
  if (drive_ == nullptr || generation != generation_ || gDrivesHalted.load(std::memory_order_relaxed)) return nullptr;
  const int n = std::min(clock.numSamples, kMaxBlockSamples);
  if (computedBlock_ == clock.block) {  // a second FrictionDrive of the slot in this block: 0
    another = true;
    return nullptr;
  }
  // A gap (no FrictionDrive ran last block): the slew starts again from the magnet off.
  if (computedBlock_ != clock.block - 1) drive_->off();
  computedBlock_ = clock.block;
  int framedSamples = 0;
  const float* combined = force.combinedOf(clock.block - 1, framedSamples);
  if (combined == nullptr) {
    // No writer framed the previous block: off at once, as the board (Device::requestOff).
    drive_->off();
    std::fill_n(samples_, n, 0.0f);
    return samples_;
  }
  const int m = std::min(n, framedSamples);
  drive_->process(combined, m, samples_);
  if (m < n) drive_->process(gNoForce, n - m, samples_ + m);  // a block size change: the rest at the minimum
  return samples_;
}

SlotDrive* driveOfSlot(int index) { return isValidSlot(index) ? &gDrives[index] : nullptr; }

bool publishDriveIfSameDevice(int index, uint32_t generation, const Device* device, AudioDrive*& drive) {
  // The generation names the device wherever and whenever it was opened: a device opened at the
  // address of a closed one has another. The pointer as well: the NRT stage's two reads are not
  // one, and an exchange between them (generation first, then device) pairs the new generation
  // with the old device, which the pointer tells apart.
  if (!isValidSlot(index) || generationOfSlot(index) != generation || peekSlot(index) != device) return false;
  drive = gDrives[index].publish(drive, generation);
  return true;
}

void haltAllDrives() { gDrivesHalted.store(true, std::memory_order_relaxed); }

bool drivesHalted() { return gDrivesHalted.load(std::memory_order_relaxed); }

}  // namespace kf::sc
