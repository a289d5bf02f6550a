// The slot handover under ThreadSanitizer (built into the TSan executable of tests/device): an
// "audio" thread runs blocks as the UGens do (viewSlot and its trajectory, the force of two
// writers per slot through SlotForce to the device, a re-base now and then) and the RT stages
// of the commands between blocks (exchangeSlot), while an "NRT" thread opens realtime devices,
// hands them over into slots already in use, reads their status, records, and closes and
// deletes what the RT stage handed back, and each device's own thread pumps. The two threads
// meet only through lock-free queues, as scsynth's stages do.
#include <unistd.h>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "DeviceFactory.hpp"
#include "DeviceSlots.hpp"
#include "core/SpscQueue.hpp"

using namespace kf;
using namespace kf::sc;
using namespace std::chrono_literals;

namespace {

constexpr int kSlots = 3;
constexpr int kBlock = 64;
constexpr double kSampleDurS = 1.0 / 48000.0;

struct Handover {
  int slot = -1;
  Device* device = nullptr;
};

// FrictionOut's sink: frames to the device, what it commanded back.
struct Sink {
  Device* device;
  float operator()(double frameTimeS, float forceN, double frameEndS) const {
    device->pushForceFrame(ForceFrame{frameTimeS, forceN, frameEndS});
    return device->commandedForceN();
  }
};

std::string tempPath(int i) {
  const char* dir = std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp";
  return std::string(dir) + "/kf-handover-" + std::to_string(::getpid()) + "-" + std::to_string(i) + ".kfsession";
}

}  // namespace

TEST_CASE("slots handed over, re-based, recorded and closed while blocks read and write them") {
  SpscQueue<Handover> toAudio(64), toNrt(64);
  std::atomic<bool> stop{false};
  std::atomic<int64_t> blocks{0}, entries{0}, frames{0};

  std::thread audio([&] {
    TrajectoryReconstructor readers[kSlots];
    float force[kBlock];
    for (int64_t block = 0; !stop.load(); ++block) {
      // RT stages run between blocks.
      Handover h;
      while (toAudio.pop(h)) toNrt.push(Handover{h.slot, exchangeSlot(h.slot, h.device)});
      const BlockClock clock{block, block * kBlock * kSampleDurS, kSampleDurS, kBlock};
      for (int slot = 0; slot < kSlots; ++slot) {
        const SlotView view = viewSlot(slot, clock);
        if (view.device == nullptr) continue;
        readers[slot] = view.trajectory->reference(TrajectoryMode::Linear);
        entries.fetch_add(view.trajectory->numEntries(), std::memory_order_relaxed);
        if (block % 97 == 0) requestSlotPosition(slot, 0.0, 0.0);  // kfZero's RT stage
        SlotForce* combined = forceOfSlot(slot);
        if (combined->registeredWriters() == 0) {
          combined->registerWriter();
          combined->registerWriter();
        }
        Sink sink{view.device};
        for (int writer = 0; writer < 2; ++writer) {
          for (int i = 0; i < kBlock; ++i) force[i] = 0.2f + 0.1f * static_cast<float>((block + i + writer) % 7);
          if (combined->write(clock, force, kBlock, sink)) frames.fetch_add(1, std::memory_order_relaxed);
        }
      }
      blocks.fetch_add(1, std::memory_order_relaxed);
      std::this_thread::sleep_for(1ms);
    }
  });

  // The NRT thread: every open goes into a slot (handing over the device there), the device
  // handed back is deleted here, as the commands' last stage does.
  auto handOver = [&](int slot, Device* device) {
    REQUIRE(toAudio.push(Handover{slot, device}));
    Handover back;
    while (!toNrt.pop(back)) std::this_thread::sleep_for(200us);
    deleteRetired(back.device);
  };
  std::string error;
  for (int round = 0; round < 12; ++round) {
    const int slot = round % kSlots;
    auto device = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::speeds({{100.0, 5.0}}), false, &error);
    REQUIRE(device);
    handOver(slot, device.release());
    std::this_thread::sleep_for(30ms);
    // Status and recording of a device in a slot, from the NRT thread (kfStatus, kfRecord).
    if (Device* inSlot = peekSlot(slot)) {
      (void)inSlot->telemetry();
      if (round % 4 == 1) {
        REQUIRE(inSlot->startRecording(tempPath(slot), error));
        std::this_thread::sleep_for(30ms);
        inSlot->stopRecording();
      }
    }
    if (round % 5 == 4) handOver(slot, nullptr);  // kfClose
  }
  for (int slot = 0; slot < kSlots; ++slot) handOver(slot, nullptr);
  stop = true;
  audio.join();
  for (int slot = 0; slot < kSlots; ++slot) std::remove(tempPath(slot).c_str());
  CHECK(blocks.load() > 100);
  CHECK(entries.load() > 0);
  CHECK(frames.load() > 100);
}
