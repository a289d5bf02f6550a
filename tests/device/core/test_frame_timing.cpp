// Realtime: force frames leave the device thread at their own time (the jitter buffer), one
// per millisecond, whatever the audio block size; the watchdog does not chatter when the audio
// period is longer than its timeout, and turns the magnet off when the frames stop. Timing
// bounds are loose (a loaded 2-core machine); the measured figures are printed. These claims
// need the threads to get the CPU on time, which realtime scheduling gives: where it is refused
// they are not checked (the test says so), only what holds at any priority; the exact tests
// below show the mechanism on a clock of their own.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "ForcePathSupport.hpp"
#include "core/Device.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;
using kf::test::TimelineSink;

namespace {

struct StreamResult {
  TelemetrySnapshot telemetry;
  std::vector<TimelineSink::Event> events;
  double lastPushS = 0.0;
  int framesPushed = 0;
  // Both the audio stand-in and the device thread got SCHED_FIFO.
  bool realtime = false;
  // The audio stand-in's wake-ups whose first block went out more than 5 ms after its end.
  int lateWakeups = 0;
};

// The body of streamFrames, on the calling thread.
StreamResult streamFramesHere(int blockSamples, double seconds, double stopWaitS) {
  const DeviceSpec spec;
  auto sink = std::make_shared<TimelineSink>();
  Device device(spec, std::make_shared<ReplayBackend>(std::vector<TimedReport>{}), sink, false);
  sink->setClock([&device] { return device.nowS(); });
  device.start();
  const double blockS = blockSamples / 48000.0;
  StreamResult result;
  int frame = 0;
  for (int block = 1; block * blockS < seconds; ++block) {
    const double blockEndS = block * blockS;
    bool slept = false;
    for (; device.nowS() < blockEndS; slept = true) std::this_thread::sleep_for(std::chrono::microseconds(100));
    if (slept && device.nowS() - blockEndS > 0.005) ++result.lateWakeups;
    for (; (frame + 1) * 0.001 <= blockEndS + 1e-12; ++frame)
      device.pushForceFrame({frame * 0.001, 0.2f + 0.001f * static_cast<float>(frame % 1000), (frame + 1) * 0.001});
    result.lastPushS = device.nowS();
  }
  result.framesPushed = frame;
  std::this_thread::sleep_for(std::chrono::duration<double>(stopWaitS));
  result.telemetry = device.telemetry();
  result.events = sink->events();
  result.realtime = result.telemetry.deviceThread.priority > 0;
  device.close();
  return result;
}

// Stands in for FrictionOut on an audio thread with blocks of `blockSamples` at 48 kHz: at
// each block's end, the frames completed in it, stamped as FrictionOut stamps them (audio time
// = device time here). Frame j carries a force that names it. Runs realtime where allowed, as
// scsynth's audio thread does (below the device thread): at normal priority two CPU hogs hold
// it up past the 10 ms watchdog.
StreamResult streamFrames(int blockSamples, double seconds, double stopWaitS) {
  StreamResult result;
  std::thread audio([&] {
    const bool realtime = scheduleThisThread("audio", {0, kFallbackPriority - 1}).priority > 0;
    result = streamFramesHere(blockSamples, seconds, stopWaitS);
    result.realtime = result.realtime && realtime;
  });
  audio.join();
  return result;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

void print(const char* name, const StreamResult& r) {
  const TelemetrySnapshot& t = r.telemetry;
  const double pumps =
      static_cast<double>(t.framesPerPump[0] + t.framesPerPump[1] + t.framesPerPump[2] + t.framesPerPump[3]);
  std::printf(
      "%s: %d frames; pumps releasing 0/1/2/3+ frames: %.3f/%.3f/%.3f/%.3f; offset from due p50 %.3f ms p99 %.3f ms "
      "max %.3f ms; release latency %.2f ms; late %llu; watchdog trips %llu; missed deadlines %llu, skipped %llu; %s, "
      "audio wake-ups over 5 ms late %d\n",
      name, r.framesPushed, t.framesPerPump[0] / pumps, t.framesPerPump[1] / pumps, t.framesPerPump[2] / pumps,
      t.framesPerPump[3] / pumps, t.frameOffset.p50S * 1e3, t.frameOffset.p99S * 1e3, t.frameOffset.maxS * 1e3,
      t.releaseLatencyS * 1e3, static_cast<unsigned long long>(t.lateFrames),
      static_cast<unsigned long long>(t.watchdogTrips), static_cast<unsigned long long>(t.missedDeadlines),
      static_cast<unsigned long long>(t.skippedFrames), r.realtime ? "realtime" : "normal priority", r.lateWakeups);
}

// What the stream's timing claims stand on: both threads getting the CPU on time. Without
// realtime scheduling, measured beside two CPU hogs on 2 cores (27 runs of each test), the
// device thread missed up to 336 of 1500 deadlines and the stand-in was held up to 23 ms: the
// watchdog then rightly trips, and the one-frame-per-ms spacing holds only as far as the
// threads happened to get the CPU. So there the test says so and checks what holds at any
// priority: each watchdog trip needs the frames to have run out, that is a late wake-up of
// the audio stand-in (lateWakeups): the frame after the last one sent was not pushed 10 ms
// after that one went out at its due time (its start plus the release latency, >= 1 ms, and at
// 1024 samples about the block period, as each burst's first frames are that late), so its
// block went out more than 10 ms + latency - 2.5 ms - block period, over 5 ms, after its end.
bool timingChecked(const StreamResult& r) {
  if (!r.realtime)
    WARN(
        "realtime scheduling refused (audio stand-in and device thread at normal priority): the timing claims "
        "(one frame per pump, 1 ms spacing, watchdog quiet) are not checked, only what holds at any priority; "
        << r.lateWakeups << " wake-ups of the audio stand-in more than 5 ms late");
  return r.realtime;
}

}  // namespace

TEST_CASE("realtime frames leave one per ms at their own time with 64-sample blocks", "[timing][wallclock]") {
  const StreamResult r = streamFrames(64, 1.5, 0.05);
  print("64 samples at 48 kHz", r);
  std::vector<TimelineSink::Event> commands;
  for (const auto& e : r.events)
    if (!e.off) commands.push_back(e);
  // Every frame reached the magnet, once, in order (none overwritten in the same pump), but for
  // those a pump that missed its deadlines skipped as stale (counted; another realtime thread
  // on a loaded machine can hold the device thread up).
  const uint64_t skipped = r.telemetry.skippedFrames;
  REQUIRE(commands.size() + skipped == static_cast<size_t>(r.framesPushed));
  // A pump woken d late (k = floor(d / 1 ms) deadlines missed) finds due the frames of the
  // k + 1 ms since the last pump's window, at most k + 2, sends one and skips at most k + 1
  // <= 2k: so at most twice the missed deadlines in all (CI saw 29 skipped for 25 missed).
  CHECK(skipped <= 2 * r.telemetry.missedDeadlines);
  for (size_t j = 0, frame = 0; j < commands.size(); ++j, ++frame) {
    while (frame < j + skipped && commands[j].forceN != 0.2f + 0.001f * static_cast<float>(frame % 1000)) ++frame;
    CHECK(commands[j].forceN == 0.2f + 0.001f * static_cast<float>(frame % 1000));
  }
  CHECK(r.telemetry.frameOffset.count + skipped == static_cast<uint64_t>(r.framesPushed));
  // At most the trip after the stream ended, and one for each time the audio stalled.
  CHECK(r.telemetry.watchdogTrips <= 1 + static_cast<uint64_t>(r.lateWakeups));
  if (!timingChecked(r)) return;
  // Spaced by the frame period: the median gap is 1 ms, and most pumps release exactly one.
  std::vector<double> gaps;
  for (size_t j = 1; j < commands.size(); ++j) gaps.push_back(commands[j].timeS - commands[j - 1].timeS);
  CHECK(median(gaps) == Approx(0.001).margin(0.0002));
  const TelemetrySnapshot& t = r.telemetry;
  const double pumps =
      static_cast<double>(t.framesPerPump[0] + t.framesPerPump[1] + t.framesPerPump[2] + t.framesPerPump[3]);
  // One per pump is the most common by far on an idle machine (0.76 measured at load 10; the exact
  // tests below show the mechanism); here the device thread's wake-ups decide.
  CHECK(t.framesPerPump[1] > t.framesPerPump[0]);
  CHECK(t.framesPerPump[1] > t.framesPerPump[2] + t.framesPerPump[3]);
  CHECK(pumps > 0);
  // Each left within a pump period of its due time (start + latency), mostly.
  CHECK(t.frameOffset.p50S < 0.001);
  // Without the buffer a 1.33 ms block carries 1 or 2 frames: a quarter of them would share a
  // pump with the next and be overwritten before reaching the magnet.
}

TEST_CASE("a long audio period raises the release latency and the watchdog does not chatter", "[timing][wallclock]") {
  // 1024 samples at 48 kHz: frames arrive in bursts of 21 every 21.3 ms, longer than the 10 ms
  // watchdog.
  const StreamResult r = streamFrames(1024, 1.5, 0.0);
  print("1024 samples at 48 kHz", r);
  CHECK(r.telemetry.releaseLatencyS > 0.8 * 1024 / 48000.0);  // about one period (bursts are that late)
  // Only where the audio stalled. With realtime scheduling too: a fresh clone's sanitized run
  // (beside the 10^9-sample drift test) had one trip after one wake-up of the SCHED_FIFO stand-in
  // over 5 ms late, the machine holding even that thread (its vCPU paused: the witness of the
  // realtime tests measured such stalls up to 24 ms). The frames did run out; tripping was right.
  CHECK(r.telemetry.watchdogTrips <= static_cast<uint64_t>(r.lateWakeups));
  if (!timingChecked(r)) return;
  std::vector<double> gaps;
  std::vector<TimelineSink::Event> commands;
  for (const auto& e : r.events)
    if (!e.off && e.timeS > 0.3) commands.push_back(e);
  for (size_t j = 1; j < commands.size(); ++j) gaps.push_back(commands[j].timeS - commands[j - 1].timeS);
  CHECK(median(gaps) == Approx(0.001).margin(0.0002));
  const TelemetrySnapshot& t = r.telemetry;
  CHECK(t.framesPerPump[1] > t.framesPerPump[0]);
  CHECK(t.framesPerPump[1] > t.framesPerPump[2] + t.framesPerPump[3]);
}

TEST_CASE("realtime: the magnet goes off about 10 ms after the last frame went out", "[timing][wallclock]") {
  const StreamResult r = streamFrames(64, 0.3, 0.1);
  double lastCommandS = 0.0;
  double offS = -1.0;
  for (const auto& e : r.events) {
    if (!e.off) lastCommandS = e.timeS;
    if (e.off && offS < 0.0 && e.timeS > lastCommandS) offS = e.timeS;
  }
  REQUIRE(offS > 0.0);
  std::printf("watchdog: magnet off %.2f ms after the last frame went out\n", (offS - lastCommandS) * 1e3);
  CHECK(offS - lastCommandS >= 0.010);
  CHECK(offS - lastCommandS < 0.030);  // 10 ms + pump period, plus room for a loaded machine
  CHECK(r.telemetry.watchdogTrips == 1);
}

// The same jitter buffer on a clock of the test's own (DeviceOptions::externalPump): exact.
namespace {

struct ExactRun {
  std::vector<TimelineSink::Event> commands;
  TelemetrySnapshot telemetry;
  int maxPerPump = 0;
  std::vector<double> latencyS;  // after each pump
};

// A realtime device (jitter buffer, watchdog) pumped by the test on a clock of its own, which
// its sink reads too.
struct PumpedDevice {
  static DeviceOptions externalPump() {
    DeviceOptions options;
    options.externalPump = true;
    return options;
  }
  double nowS = 0.0;
  std::shared_ptr<TimelineSink> sink = std::make_shared<TimelineSink>();
  Device device{DeviceSpec{}, std::make_shared<ReplayBackend>(std::vector<TimedReport>{}), sink, false, externalPump()};
  PumpedDevice() {
    sink->setClock([this] { return nowS; });
  }
};

// An audio thread that delivers nothing from startS for stallS, then catches up at once; or a
// device thread that does not wake in that time, then pumps once, passing the deadline it missed.
struct Stall {
  double startS = 0.0, stallS = 0.0;
};

// Audio blocks of blockSamples at rateHz push their completed frames at each block's end; the
// device is pumped every 1 ms, its pumps offset from the audio clock by pumpPhaseS.
ExactRun runExact(int blockSamples, double rateHz, double seconds, double pumpPhaseS, Stall stall = {},
                  Stall pumpStall = {}) {
  PumpedDevice pumped;
  auto& [nowS, sink, device] = pumped;
  device.start();
  const double blockS = blockSamples / rateHz;
  int frame = 0;
  int block = 1;
  ExactRun run;
  double missedS = -1.0;  // the first deadline the device thread slept through
  for (int pump = 1; pump * 0.001 + pumpPhaseS < seconds; ++pump) {
    const double pumpS = pump * 0.001 + pumpPhaseS;
    const bool stalled = pumpS >= stall.startS && pumpS < stall.startS + stall.stallS;
    for (; !stalled && block * blockS <= pumpS; ++block)  // the audio blocks that ended before this pump
      for (; (frame + 1) * 0.001 <= block * blockS + 1e-12; ++frame)
        device.pushForceFrame({frame * 0.001, 0.2f + 0.001f * static_cast<float>(frame % 1000), (frame + 1) * 0.001});
    if (pumpS >= pumpStall.startS && pumpS < pumpStall.startS + pumpStall.stallS) {
      if (missedS < 0.0) missedS = pumpS;
      continue;
    }
    const size_t before = sink->commands().size();
    device.pump(nowS = pumpS, missedS);
    missedS = -1.0;
    run.maxPerPump = std::max(run.maxPerPump, static_cast<int>(sink->commands().size() - before));
    run.latencyS.push_back(device.telemetry().releaseLatencyS);
  }
  run.commands = sink->commands();
  run.telemetry = device.telemetry();
  return run;
}

}  // namespace

TEST_CASE("exact: one frame per 1 ms pump, each at its start plus the latency, at any block size and rate",
          "[timing]") {
  for (double rateHz : {44100.0, 48000.0, 96000.0, 192000.0})
    for (int blockSamples : {1, 64, 128, 256})
      for (double phaseS : {0.0, 0.0003, 0.0007}) {
        if (blockSamples / rateHz > 0.0025) continue;  // longer periods: the next test
        INFO(rateHz << " Hz, " << blockSamples << " samples, pump phase " << phaseS);
        const ExactRun run = runExact(blockSamples, rateHz, 0.5, phaseS);
        CHECK(run.maxPerPump == 1);
        CHECK(run.telemetry.watchdogTrips == 0);
        CHECK(run.telemetry.lateFrames == 0);
        REQUIRE(run.commands.size() > 480);
        // The latency: what the frames were measured to need to arrive (their period, the audio
        // block, the pump that takes them), never less than a frame period.
        const double latencyS = run.telemetry.releaseLatencyS;
        CHECK(latencyS >= 0.001);
        CHECK(latencyS <= 0.001 + blockSamples / rateHz + 0.001 + 1e-9);
        for (size_t j = 0; j < run.commands.size(); ++j) {
          // Frame j starts at j ms and goes out at the pump nearest j ms + latency; until the
          // first frames have set the latency, perhaps a pump later.
          CHECK(run.commands[j].forceN == 0.2f + 0.001f * static_cast<float>(j % 1000));
          if (run.commands[j].timeS > 0.01)
            CHECK(std::abs(run.commands[j].timeS - (j * 0.001 + latencyS)) <= 0.0005 + 1e-9);
        }
      }
}

TEST_CASE("exact: the latency is estimated from the audio period, then measured from the first frame", "[timing]") {
  // Before any frame: its period, the host's audio period and a pump (here 256 samples at 48 kHz);
  // from the first frame on what the frames need, at once: 64-sample blocks need less.
  DeviceOptions options = PumpedDevice::externalPump();
  options.audioPeriodS = 256 / 48000.0;
  Device device(DeviceSpec{}, std::make_shared<ReplayBackend>(std::vector<TimedReport>{}),
                std::make_shared<CountingForceSink>(), false, options);
  device.pump(0.0005);
  CHECK(device.telemetry().releaseLatencyS == Approx(0.001 + 256 / 48000.0 + 0.001));
  const ExactRun run = runExact(64, 48000.0, 2.0, 0.0004);
  for (double latencyS : run.latencyS) {  // no estimate left over: one frame per pump from the first
    CHECK(latencyS >= 0.001);
    CHECK(latencyS <= 0.001 + 64 / 48000.0 + 0.001);
  }
  CHECK(run.maxPerPump == 1);
}

TEST_CASE("exact: without the jitter buffer a quarter of the frames would share a pump", "[timing]") {
  // What the device did before: every queued frame applied at the pump that finds it. At 48 kHz
  // with 64-sample blocks, 1.333 ms apart, a third of the blocks carry two frames.
  int blocksWithTwo = 0, frames = 0, blocks = 0;
  for (int block = 1, frame = 0; block * 64 / 48000.0 < 1.0; ++block, ++blocks) {
    int here = 0;
    for (; (frame + 1) * 0.001 <= block * 64 / 48000.0 + 1e-12; ++frame) ++here;
    frames += here;
    if (here == 2) ++blocksWithTwo;
  }
  CHECK(static_cast<double>(blocksWithTwo) / frames == Approx(0.25).margin(0.01));
  const ExactRun run = runExact(64, 48000.0, 1.0, 0.0002);
  CHECK(run.maxPerPump == 1);  // with it: none
}

TEST_CASE("exact: long audio periods raise the latency once and the watchdog never trips", "[timing]") {
  for (int blockSamples : {512, 1024, 2048, 4096}) {
    INFO(blockSamples << " samples at 48 kHz");
    const ExactRun run = runExact(blockSamples, 48000.0, 2.0, 0.0004);
    CHECK(run.telemetry.watchdogTrips == 0);  // 85 ms between bursts at 4096 samples
    CHECK(run.telemetry.releaseLatencyS >= blockSamples / 48000.0);
    // After the first burst set the latency, one frame per pump.
    int afterFirst = 0;
    for (size_t j = 1; j < run.commands.size(); ++j)
      if (run.commands[j].timeS > 0.2 && run.commands[j].timeS - run.commands[j - 1].timeS < 0.0005) ++afterFirst;
    CHECK(afterFirst == 0);
  }
}

TEST_CASE("exact: a stall raises the latency, which comes back down within 1.5 s", "[timing]") {
  // 48 kHz, 64-sample blocks; the audio thread stalls 8 ms at 1 s (below the 10 ms watchdog).
  const ExactRun run = runExact(64, 48000.0, 4.0, 0.0004, Stall{1.0, 0.008});
  CHECK(run.telemetry.watchdogTrips == 0);
  const double steadyS = run.latencyS[900];  // before the stall
  CHECK(steadyS <= 0.0035);
  const double peakS = *std::max_element(run.latencyS.begin(), run.latencyS.end());
  CHECK(peakS >= 0.008);  // the frames caught up after the stall needed it
  // Back to the steady latency 1.5 s after the stall (pump 2509, at 2.5094 s).
  CHECK(run.latencyS[2508] == Approx(steadyS).margin(1e-9));
  CHECK(run.latencyS.back() == Approx(steadyS).margin(1e-9));
  // Coming down 1 ms means one frame more in some pump: as many shared pumps as milliseconds of
  // excess latency, in the recovery alone, and never more than two frames in a pump.
  int sharedPumps = 0;
  for (size_t j = 1; j < run.commands.size(); ++j)
    if (run.commands[j].timeS == run.commands[j - 1].timeS) {
      ++sharedPumps;
      CHECK(run.commands[j].timeS > 1.0);
      CHECK(run.commands[j].timeS < 2.6);
    }
  CHECK(sharedPumps <= static_cast<int>(std::ceil((peakS - steadyS) / 0.001)));
  CHECK(run.maxPerPump <= 2);
}

TEST_CASE("exact: a late device thread skips the stale frames and sends the newest, the latency stays", "[timing]") {
  // 48 kHz, 64-sample blocks; the device thread sleeps through 6 deadlines at 1 s (the audio
  // goes on), then pumps once at 1.0064 s, passing the first deadline it missed.
  const ExactRun run = runExact(64, 48000.0, 2.0, 0.0004, Stall{}, Stall{1.0, 0.006});
  const ExactRun steady = runExact(64, 48000.0, 2.0, 0.0004);
  CHECK(run.telemetry.watchdogTrips == 0);
  // Not raised: the pump's own lateness is not the frames'.
  CHECK(run.telemetry.releaseLatencyS == Approx(steady.telemetry.releaseLatencyS).margin(1e-9));
  CHECK(*std::max_element(run.latencyS.begin(), run.latencyS.end()) == Approx(steady.telemetry.releaseLatencyS));
  // The 6 frames the missed pumps would have sent: skipped, not sent in a burst; the pump after
  // the stall sends one frame, the one it sends without a stall, and all go on as without.
  CHECK(run.maxPerPump == 1);
  CHECK(run.telemetry.skippedFrames == 6);
  REQUIRE(run.commands.size() + 6 == steady.commands.size());
  size_t after = 0;
  while (after < run.commands.size() && run.commands[after].timeS < 1.006) ++after;
  REQUIRE(after > 0);
  CHECK(run.commands[after - 1].timeS < 1.0);
  CHECK(run.commands[after].timeS == Approx(1.0064));
  for (size_t j = after; j < run.commands.size(); ++j) {
    CHECK(run.commands[j].timeS == steady.commands[j + 6].timeS);
    CHECK(run.commands[j].forceN == steady.commands[j + 6].forceN);
  }
  CHECK(steady.telemetry.skippedFrames == 0);
}

TEST_CASE("exact: the magnet goes off 10 ms after the last frame went out", "[timing]") {
  PumpedDevice pumped;
  auto& [nowS, sink, device] = pumped;
  for (int i = 0; i < 100; ++i) device.pushForceFrame({i * 0.001, 1.0f, (i + 1) * 0.001});
  for (int pump = 1; pump < 200; ++pump) device.pump(nowS = pump * 0.001);
  const auto commands = sink->commands();
  const auto offs = sink->offTimes();
  REQUIRE(commands.size() == 100);
  REQUIRE(offs.size() == 1);
  CHECK(offs[0] - commands.back().timeS >= 0.010 - 1e-9);
  CHECK(offs[0] - commands.back().timeS <= 0.011 + 1e-9);  // the pump at or after 10 ms
}
