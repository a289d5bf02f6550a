// The end-to-end scene (issue 37, item 4): scsynth with our plugin runs in the guest (JACK's dummy
// driver), sclang runs on the host and reaches it through QEMU's user network (the host side:
// tests/kernel/scene_host.py), and FrictionDevice.hardware opens the guest's USB mouse (QEMU's,
// moved here through QMP) and the gadget board (kf_board_gadget on dummy_hcd). A synth plays the
// pilot (FrictionPilot.ar: FrictionMouseIn -> SpatialBufRd -> LoudnessToFriction -> FrictionOut)
// and writes its position and forces on control buses 0..2, which this test reads from scsynth.
// Each move of the mouse must move the position by its counts, and the board must receive the
// drive the pilot mapping gives for the signal under the puck.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "LoudnessToFriction.hpp"
#include "PaperProfile.hpp"
#include "board/BoardProtocol.hpp"
#include "guest/GadgetBoard.hpp"
#include "guest/GuestSystem.hpp"
#include "guest/HostHook.hpp"
#include "guest/QemuInput.hpp"
#include "scene/AudioServer.hpp"
#include "scene/OscClient.hpp"

using namespace kf::guest;
using namespace std::chrono_literals;

namespace {

constexpr int kScsynthPort = 57110;  // the host reaches it as QEMU's hostfwd says
// The scene's mouse profile: one count is one sample of the pilot signal at mapping 3 (8 samples
// per mm), so that the puck rests on samples, which the spatial reader returns exactly.
constexpr double kCountMm = 0.125;
constexpr double kSamplesPerMm = kf::paper::pilot::mapping3SamplesPerMm;
constexpr double kGuardS = 30.0;  // hang guards, not timing tolerances
// The forces the plugin gives against equation (2) in double here: LoudnessToFriction's fast
// logarithm adds at most kMaxFastLogErrorN (its own bound), and the force is a float on the
// buses, which rounds it by half an ulp: 2^-25 of a force below 1 N, 3e-8 N.
constexpr double kForceToleranceN = kf::LoudnessToFriction::kMaxFastLogErrorN + 3e-8;
// The board's drive: that force error is (5.3e-7 / 1.26 N) x 65535 = 0.03 drive units, so the
// device's lround and this test's may differ by the one unit a value near .5 rounds to, no more.
constexpr long kDriveToleranceUnits = 1;

int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The pilot signal's sample i, as sclang makes it (FrictionPilot.signal: sin(2 pi i / 100) in
// double, stored as float).
double pilotSample(long i) {
  return static_cast<float>(std::sin(2.0 * M_PI * static_cast<double>(i) / kf::paper::pilot::cycleFrames));
}

// Equations (1) and (2) with the paper's numbers (profiles/paper.json), written out here: the
// 1 ms mean |a| of a puck at rest is |a| itself; its level in dB, [-30, 0] dB onto [0.14, 0.5] N.
double pilotForceN(double sample) {
  namespace m = kf::paper::mapping;
  const double db = 20.0 * std::log10(std::abs(sample) / m::ref);
  const double level = std::isfinite(db) ? std::clamp((db - m::loDb) / (m::hiDb - m::loDb), 0.0, 1.0) : 0.0;
  return m::loForceN + level * (m::hiForceN - m::loForceN);
}

// The board's drive for a force, with no calibration table (linear: 0 at the device's minimum,
// full at its maximum) and no derating (these forces heat the coil far below its rated duty).
long driveFor(double forceN) {
  namespace d = kf::paper::device;
  return std::lround((forceN - d::minForceN) / (d::maxForceN - d::minForceN) * kf::board::kDriveFull);
}

// The drives of frames[from..] and how many times each came: " 18724 x312 ...".
std::string drivesOf(const std::vector<GadgetFrame>& frames, size_t from) {
  std::map<int, int> histogram;
  for (size_t i = from; i < frames.size(); ++i) ++histogram[frames[i].drive];
  std::string seen;
  for (const auto& [value, n] : histogram) seen += " " + std::to_string(value) + " x" + std::to_string(n);
  return seen;
}

}  // namespace

TEST_CASE(
    "scene: sclang on the host plays the pilot on scsynth in the guest, the USB mouse moves it and the "
    "gadget board receives its forces",
    "[scene]") {
  // The board is a machine of its own; here it shares the guest's one CPU with the audio chain
  // (jackd, scsynth, the device's threads at realtime priority): below them, so that it takes
  // what they leave, as a board's own processor would not take theirs.
  GadgetBoard gadget(GadgetBoard::kSerial, {"--priority", "1"});
  networkUp();
  AudioServer server(kScsynthPort);
  HostHook& hook = HostHook::instance();
  REQUIRE(hook.host("scene", "start") == "ok");
  std::string state;
  REQUIRE(waitUntil(
      [&] {
        state = hook.host("scene", "state");
        return state != "waiting";
      },
      120.0));
  INFO("sclang: " << state);
  REQUIRE(state == "ready");
  const int64_t readyNs = nowNs();
  OscClient osc(kScsynthPort);
  gadget.report();  // the frames of the set-up are not the scene's

  long counts = 0;
  std::string figures = "counts injected -> position read, drive expected -> received (latency):";
  for (const int dx : {25, -20, 45, -48, 10}) {
    counts += dx;
    const float expectedMm = static_cast<float>(counts * kCountMm);
    const double forceN = pilotForceN(pilotSample(std::lround(counts * kCountMm * kSamplesPerMm)));
    const long drive = driveFor(forceN);
    const int64_t movedNs = nowNs();
    qemuMove(dx, 0);
    // The puck follows the counts: FrictionMouseIn's position on bus 0 (a multiple of 1/8 mm,
    // exact in float).
    std::vector<float> buses;
    const bool moved = waitUntil(
        [&] {
          buses = osc.controlBuses(0, 3);
          return buses[0] == expectedMm;
        },
        kGuardS);
    INFO("after " << counts << " counts the position is " << buses[0] << " mm, expected " << expectedMm);
    REQUIRE(moved);
    // Bus 1: the force the mapping requests, bus 2: FrictionOut's commanded force (float). The
    // force is the resting puck's once LoudnessToFriction's window holds only its samples: read at
    // the first poll that saw the new position it was still the moving puck's on a slow guest
    // (0.49935 N for 0.5 N, a fresh clone). A force that never comes is still a failure below.
    waitUntil(
        [&] {
          buses = osc.controlBuses(0, 3);
          return std::fabs(buses[1] - forceN) <= kForceToleranceN;
        },
        kGuardS);
    CHECK(buses[1] == Approx(forceN).margin(kForceToleranceN));
    // The board: the set-points take the drive of that force once the frames carrying it reach it.
    std::vector<GadgetFrame> frames;
    const auto received = [&] {
      const GadgetReport report = gadget.report();
      for (const auto& f : report.applied())
        if (f.timeNs > movedNs) frames.push_back(f);
      for (const auto& f : frames)
        if (std::labs(f.drive - drive) <= kDriveToleranceUnits) return true;
      return false;
    };
    const auto receivedEvery100Ms = [&] {
      std::this_thread::sleep_for(100ms);  // the gadget's report is not asked for more often
      return received();
    };
    const bool reached = waitUntil(receivedEvery100Ms, kGuardS);
    INFO("the drives the board received since the move:" << drivesOf(frames, 0));
    REQUIRE(reached);
    std::this_thread::sleep_for(300ms);  // and it holds while the puck rests
    received();
    size_t first = 0;
    while (std::labs(frames[first].drive - drive) > kDriveToleranceUnits) ++first;
    CHECK(osc.controlBuses(2, 1)[0] == Approx(forceN).margin(kForceToleranceN));
    // Once the board has the new drive, every set-point carries it while the puck rests.
    const long others = std::count_if(frames.begin() + first, frames.end(), [&](const GadgetFrame& f) {
      return std::labs(f.drive - drive) > kDriveToleranceUnits;
    });
    INFO("the drives of the set-points from the first with " << drive << " on:" << drivesOf(frames, first));
    CHECK(others == 0);
    char step[160];
    std::snprintf(step, sizeof step, " %+d -> %.3f mm, %ld -> %u (%.0f ms);", dx, buses[0], drive, frames[first].drive,
                  (frames[first].timeNs - movedNs) / 1e6);
    figures += step;
  }
  const double playedS = (nowNs() - readyNs) / 1e9;
  const std::string done = hook.host("scene", "stop");
  INFO("sclang: " << done);
  CHECK(done == "done");
  // The device's own account, posted by scsynth at the stop (kfStatus): how many force frames
  // the audio made while the scene played, and whether its watchdog had to step in.
  const std::string status = server.statusLine();
  INFO(status);
  long frames = -1, trips = -1;
  REQUIRE(std::sscanf(status.c_str() + status.find(" frames "), " frames %ld", &frames) == 1);
  REQUIRE(std::sscanf(status.c_str() + status.find(" watchdog trips "), " watchdog trips %ld", &trips) == 1);
  CHECK(trips == 0);
  char device[200];
  std::snprintf(device, sizeof device,
                " the audio made %ld force frames in %.1f s (%.0f %% of real time), the device's watchdog tripped %ld "
                "times",
                frames, playedS, frames / playedS / 10.0, trips);
  figures += device;
  const GadgetReport after = gadget.report();
  CHECK_FALSE(after.controlsOf(0x03).empty());  // the scene's close disarmed the board
  std::printf("scene: %s\n", figures.c_str());
  reportFigure("scene", figures);
}
