// SlotDrive: a slot's audio drive drives the previous block's combined force, the same whichever
// side of the writers it runs, for the first caller of a block only (a slot has one drive), and is
// 0 at once when no writer framed the previous block, for another device's chain, or without a
// chain.
#include <catch2/catch.hpp>
#include <memory>
#include <vector>

#include "DeviceSlots.hpp"
#include "SlotDrive.hpp"

using kf::sc::BlockClock;
using kf::sc::SlotDrive;
using kf::sc::SlotForce;

namespace {

constexpr int kBlock = 64;

BlockClock clockOf(int64_t block) { return BlockClock{block, block * kBlock / 48000.0, 1.0 / 48000.0, kBlock}; }

struct NoDevice {
  float operator()(double, float forceN, double) const { return forceN; }
};

kf::DriveCircuit circuit() {
  kf::DriveCircuit c;
  c.fullScaleCurrentA = 2.0;
  c.transconductanceAPerV = 0.5;
  c.outputFullScaleV = 4.0;  // drive level = sample value
  c.maxSafeCurrentA = 2.0;
  c.magnet = kf::CalibrationTable::linear(0.14, 1.4);
  return c;
}

// A slot with one writer, its drive published for generation 7.
struct Slot {
  std::unique_ptr<SlotForce> force = std::make_unique<SlotForce>();
  std::unique_ptr<SlotDrive> drive = std::make_unique<SlotDrive>();
  NoDevice sink;
  Slot() {
    force->reset(kf::DeviceSpec{});
    force->registerWriter();
    REQUIRE(drive->publish(new kf::AudioDrive(kf::DeviceSpec{}, circuit(), 48000.0), 7) == nullptr);
  }
  ~Slot() { delete drive->publish(nullptr, 0); }
  void write(int64_t block, float forceN) {
    std::vector<float> f(kBlock, forceN);
    force->write(clockOf(block), f.data(), kBlock, sink);
  }
  // What a FrictionDrive outputs: the drive, or 0 for a second caller in a block (empty: no chain).
  std::vector<float> samples(int64_t block, uint32_t generation = 7) {
    bool another = false;
    const float* s = drive->samples(clockOf(block), generation, *force, another);
    if (another) return std::vector<float>(kBlock, 0.0f);
    return s == nullptr ? std::vector<float>{} : std::vector<float>(s, s + kBlock);
  }
};

// What AudioDrive gives for `blocks` of constant forces from the magnet off.
std::vector<float> expected(const std::vector<float>& forces) {
  kf::AudioDrive drive(kf::DeviceSpec{}, circuit(), 48000.0);
  std::vector<float> out;
  for (float f : forces) {
    std::vector<float> in(kBlock, f), block(kBlock);
    drive.process(in.data(), kBlock, block.data());
    out.insert(out.end(), block.begin(), block.end());
  }
  return out;
}

std::vector<float> slice(const std::vector<float>& v, int block) {
  return std::vector<float>(v.begin() + block * kBlock, v.begin() + (block + 1) * kBlock);
}

}  // namespace

TEST_CASE("the drive is the previous block's force, whichever side of the writer it runs", "[slot-drive]") {
  Slot slot;
  slot.write(0, 1.0f);
  const std::vector<float> before = slot.samples(1);  // before the writer of block 1
  slot.write(1, 0.5f);
  const std::vector<float> want = expected({1.0f, 0.5f});
  CHECK(before == slice(want, 0));
  slot.write(2, 0.5f);
  CHECK(slot.samples(2) == slice(want, 1));  // after the writer of block 2: still block 1's force
  CHECK(before.back() > 0.0f);
}

TEST_CASE("a second FrictionDrive of the slot in the same block gets zeros: a slot has one drive", "[slot-drive]") {
  Slot slot;
  slot.write(0, 1.4f);
  const std::vector<float> first = slot.samples(1);
  CHECK(first.back() > 0.0f);
  CHECK(slot.samples(1) == std::vector<float>(kBlock, 0.0f));  // the second caller, before the writer
  slot.write(1, 1.4f);
  CHECK(slot.samples(1) == std::vector<float>(kBlock, 0.0f));  // and after it
  // The first caller's drive goes on as if alone (the second took nothing from its slew).
  slot.write(2, 1.4f);
  CHECK(slot.samples(2) == slice(expected({1.4f, 1.4f}), 1));
}

TEST_CASE("no writer framed the previous block: 0 at once, then up from the magnet off", "[slot-drive]") {
  Slot slot;
  CHECK(slot.samples(0) == std::vector<float>(kBlock, 0.0f));  // nothing framed before block 0
  slot.write(0, 1.4f);
  slot.write(1, 1.4f);
  CHECK(slot.samples(1).back() > 0.0f);
  slot.write(2, 1.4f);
  CHECK(slot.samples(2).back() > 0.0f);
  CHECK(slot.samples(4) == std::vector<float>(kBlock, 0.0f));  // block 3 framed by nobody
  slot.write(4, 1.4f);
  CHECK(slot.samples(5) == slice(expected({1.4f}), 0));  // slewed up again from 0
}

TEST_CASE("a gap in the blocks starts the slew again from the magnet off", "[slot-drive]") {
  Slot slot;
  slot.write(0, 1.4f);
  slot.write(1, 1.4f);
  CHECK(slot.samples(1) == slice(expected({1.4f}), 0));
  slot.write(2, 1.4f);
  slot.write(3, 1.4f);
  CHECK(slot.samples(3) == slice(expected({1.4f}), 0));  // block 2 was not driven
}

TEST_CASE("another device's chain, or none, drives nothing", "[slot-drive]") {
  Slot slot;
  slot.write(0, 1.0f);
  CHECK(slot.samples(1, 8).empty());
  delete slot.drive->publish(nullptr, 7);
  CHECK(slot.samples(1).empty());
  CHECK_FALSE(slot.drive->hasDrive());
}

TEST_CASE("a reloaded drive of the same device goes on hot and slewed: its first block is still derated",
          "[slot-drive]") {
  kf::DeviceSpec spec;
  spec.heatTimeConstantS = 0.001;  // hot within a few ms at full drive
  spec.heatRatedDuty = 0.25;       // derated towards drive sqrt(0.25) = 0.5
  auto force = std::make_unique<SlotForce>();
  auto drive = std::make_unique<SlotDrive>();
  force->reset(spec);
  force->registerWriter();
  NoDevice sink;
  const std::vector<float> full(kBlock, 1.4f);
  auto run = [&](int64_t block) {  // the writer of block-1 has run; FrictionDrive of block
    force->write(clockOf(block - 1), full.data(), kBlock, sink);
    bool another = false;
    const float* s = drive->samples(clockOf(block), 7, *force, another);
    REQUIRE(s != nullptr);
    return std::vector<float>(s, s + kBlock);
  };
  REQUIRE(drive->publish(new kf::AudioDrive(spec, circuit(), 48000.0), 7) == nullptr);
  std::vector<float> hot;
  for (int64_t b = 1; b <= 75; ++b) hot = run(b);  // 100 ms at full force: 100 heat time constants
  REQUIRE(hot.back() < 0.6f);                      // derated (sample value = drive level here)
  // The same device's calibration loaded again (loadDrive, or the same file sent twice).
  delete drive->publish(new kf::AudioDrive(spec, circuit(), 48000.0), 7);
  const std::vector<float> reloaded = run(76);
  // Heat and slew go on: the first sample is the one the replaced chain would have given, the
  // rated drive 0.5 the coil was derated to (measured: equal; a cold chain's is 0.033, slewing
  // up from the magnet off; a chain with the slew but not the heat gives full drive, 1).
  CHECK(reloaded.front() == hot.back());
  CHECK(reloaded.back() < 0.6f);
  // Another device's chain starts cold, from the magnet off.
  delete drive->publish(new kf::AudioDrive(spec, circuit(), 48000.0), 8);
  force->write(clockOf(76), full.data(), kBlock, sink);
  bool another = false;
  const float* cold = drive->samples(clockOf(77), 8, *force, another);
  REQUIRE(cold != nullptr);
  CHECK(cold[0] < 0.1f);
  delete drive->publish(nullptr, 0);
}

TEST_CASE("a drive is published only for the device its NRT stage saw, told by generation", "[slot-drive]") {
  using kf::sc::exchangeSlot;
  using kf::sc::generationOfSlot;
  using kf::sc::peekSlot;
  using kf::sc::publishDriveIfSameDevice;
  constexpr int kIndex = 9;                              // no other test of this executable uses it
  const uint32_t generation = generationOfSlot(kIndex);  // stage 2: the generation, then the device
  const kf::Device* device = peekSlot(kIndex);
  // Between the stages the slot's device is replaced by one at the same address (here null, the
  // slot closed again: the pointer alone cannot tell): refused, the chain left to the caller.
  CHECK(exchangeSlot(kIndex, nullptr) == nullptr);
  kf::AudioDrive* const built = new kf::AudioDrive(kf::DeviceSpec{}, circuit(), 48000.0);
  kf::AudioDrive* chain = built;
  CHECK_FALSE(publishDriveIfSameDevice(kIndex, generation, device, chain));
  CHECK(chain == built);
  CHECK_FALSE(kf::sc::driveOfSlot(kIndex)->hasDrive());
  // A new generation read with the old device (an exchange between stage 2's two reads): refused.
  int elsewhere = 0;
  CHECK_FALSE(publishDriveIfSameDevice(kIndex, generationOfSlot(kIndex),
                                       reinterpret_cast<const kf::Device*>(&elsewhere), chain));
  // The slot unchanged since stage 2: published, the replaced chain (none) handed back.
  CHECK(publishDriveIfSameDevice(kIndex, generationOfSlot(kIndex), peekSlot(kIndex), chain));
  CHECK(chain == nullptr);
  CHECK(kf::sc::driveOfSlot(kIndex)->publish(nullptr, 0) == built);
  delete built;
}
