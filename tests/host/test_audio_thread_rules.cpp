// DESIGN's audio-thread rule, shown: what the UGens call per block never allocates and never
// locks a mutex. Global operator new and pthread_mutex_lock are counted while a thread-local
// flag marks "audio thread" code, around the very calls the UGens make: the signal cores, the
// device slot view and the device's queues, with the real device thread running alongside.
#include <catch2/catch.hpp>

#include <dlfcn.h>
#include <pthread.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <new>
#include <thread>
#include <vector>

#include "DeviceClockMapper.hpp"
#include "DeviceFactory.hpp"
#include "DeviceSlots.hpp"
#include "ForceFramer.hpp"
#include "LoudnessToFriction.hpp"
#include "SpatialReader.hpp"
#include "TrajectoryReconstructor.hpp"

namespace {

thread_local bool tInAudioCode = false;
std::atomic<int> gAllocations{0};
std::atomic<int> gLocks{0};

// Marks a scope as audio-thread code.
struct AudioSection {
  AudioSection() { tInAudioCode = true; }
  ~AudioSection() { tInAudioCode = false; }
};

}  // namespace

// Every form of the global operators is replaced, all on malloc/free: replacing only some
// (as before) pairs this file's new with the sanitizer runtime's delete[] or aligned forms,
// which AddressSanitizer rightly reports as mismatched (the "clash with Catch2").
namespace {
void* countedAlloc(std::size_t size, std::size_t alignment = 0) {
  if (tInAudioCode) gAllocations.fetch_add(1);
  if (size == 0) size = 1;
  if (alignment > alignof(std::max_align_t)) {
    void* p = nullptr;
    return ::posix_memalign(&p, alignment, size) == 0 ? p : nullptr;
  }
  return std::malloc(size);
}
void* countedAllocOrThrow(std::size_t size, std::size_t alignment = 0) {
  if (void* p = countedAlloc(size, alignment)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) { return countedAllocOrThrow(size); }
void* operator new[](std::size_t size) { return countedAllocOrThrow(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return countedAlloc(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return countedAlloc(size); }
void* operator new(std::size_t size, std::align_val_t a) { return countedAllocOrThrow(size, std::size_t(a)); }
void* operator new[](std::size_t size, std::align_val_t a) { return countedAllocOrThrow(size, std::size_t(a)); }
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return countedAlloc(size, std::size_t(a));
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return countedAlloc(size, std::size_t(a));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

extern "C" int pthread_mutex_lock(pthread_mutex_t* mutex) {
  using Lock = int (*)(pthread_mutex_t*);
  static Lock real = reinterpret_cast<Lock>(dlsym(RTLD_NEXT, "pthread_mutex_lock"));
  if (tInAudioCode) gLocks.fetch_add(1);
  return real(mutex);
}

TEST_CASE("the counters see allocations and locks in audio code") {
  gAllocations = gLocks = 0;
  std::mutex m;
  {
    AudioSection audio;
    void* volatile p = ::operator new(16);  // a call, which the compiler may not elide
    ::operator delete(p);
    m.lock();
    m.unlock();
  }
  CHECK(gAllocations == 1);
  CHECK(gLocks == 1);
}

TEST_CASE("a block of every UGen's work allocates nothing and locks nothing") {
  constexpr int kBlock = 64;
  constexpr double kSampleDurS = 1.0 / 48000;
  // Set up as the NRT stages and constructors do (allocation allowed here).
  std::vector<float> history(960), signal(24000), audio(kBlock), forceN(kBlock);
  for (size_t i = 0; i < signal.size(); ++i) signal[i] = static_cast<float>(std::sin(i * 0.0628));
  kf::LoudnessToFriction loudness(history.data(), static_cast<int>(history.size()));
  loudness.setWindowSamples(48);
  kf::TrajectoryReconstructor trajectory(125.0, kf::TrajectoryMode::Predictive);
  std::vector<float> x(kBlock), y(kBlock), vx(kBlock), vy(kBlock);

  std::string error;
  auto device = kf::openSimDevice(kf::DeviceSpec{}, kf::SimParams{}, kf::HandScript::speeds({{80.0, 2.0}}),
                                  /*lockstep=*/false, &error);
  REQUIRE(device);
  kf::Device* raw = device.get();
  REQUIRE(kf::sc::exchangeSlot(2, raw) == nullptr);

  gAllocations = gLocks = 0;
  int64_t reportsSeen = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int64_t block = 0; std::chrono::steady_clock::now() - start < std::chrono::milliseconds(400); ++block) {
    const double startS = block * kBlock * kSampleDurS;
    {
      AudioSection audioThread;
      // FrictionMouseIn
      const kf::sc::SlotView view = kf::sc::viewSlot(2, kf::sc::BlockClock{block, startS, kSampleDurS, kBlock});
      if (block == 0) trajectory = view.trajectory->reference(kf::TrajectoryMode::Predictive);
      kf::sc::addEntries(trajectory, view.trajectory->entries(), view.trajectory->numEntries());
      reportsSeen = view.trajectory->reportsTaken();
      trajectory.render(startS, kSampleDurS, kBlock, 0.0, x.data(), y.data(), vx.data(), vy.data());
      // SpatialBufRd
      const kf::SignalView sv{signal.data(), static_cast<int64_t>(signal.size()), 1};
      float* audioOut[] = {audio.data()};
      kf::readSpatialBlock(sv, x.data(), 1, 0.0, 500.0, kf::Interpolation::Cubic, audioOut, kBlock);
      // LoudnessToFriction
      loudness.process(audio.data(), forceN.data(), kBlock);
      // FrictionOut
      uint32_t generation = 0;
      kf::Device* d = kf::sc::deviceOfSlot(2, startS, &generation);
      auto sink = [d](double timeS, float f, double) {
        d->pushForceFrame(kf::ForceFrame{timeS, f, d->nowS()});
        return d->commandedForceN();
      };
      kf::sc::forceOfSlot(2)->write(kf::sc::BlockClock{block, startS, kSampleDurS, kBlock}, forceN.data(), kBlock,
                                    sink);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(1333));  // a block of real time
  }
  kf::Device* retired = kf::sc::exchangeSlot(2, nullptr);
  const kf::TelemetrySnapshot telemetry = device->telemetry();
  device.release();
  kf::sc::deleteRetired(retired);

  CHECK(reportsSeen > 20);  // the device thread really delivered while we watched
  CHECK(gAllocations == 0);
  CHECK(gLocks == 0);
  // The latencies were measured on the way. How close the loop keeps to 1 ms is a speed goal,
  // measured by the bench (bench/REPORT.md, loop period); here, on a shared machine, only that
  // the periods were recorded and are sane (after a stall the loop catches up with short ones).
  CHECK(telemetry.pumpPeriod.count > 200);
  CHECK(telemetry.pumpPeriod.p50S > 0.0);
  CHECK(telemetry.pumpPeriod.p50S < 0.02);
  CHECK(telemetry.reportLatency.count == static_cast<uint64_t>(reportsSeen));
  CHECK(telemetry.reportLatency.p50S < 0.02);
  CHECK(telemetry.forceLatency.count > 200);
  CHECK(telemetry.forceLatency.p50S < 0.02);
}
