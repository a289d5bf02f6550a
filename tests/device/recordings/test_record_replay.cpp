#include <catch2/catch.hpp>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "DeviceFactory.hpp"
#include "core/files/SessionFile.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;

namespace {
std::string outputPath(const char* name) { return std::string(KF_TEST_OUTPUT_DIR) + "/" + name; }

bool sameReport(const MouseReport& a, const MouseReport& b) {
  return a.deviceTimeS == b.deviceTimeS && a.dxCounts == b.dxCounts && a.dyCounts == b.dyCounts &&
         a.buttons == b.buttons && a.flags == b.flags;
}

// Pumps a lockstep device every 1 ms up to endS, pushing one force frame per ms, and returns
// every report popped.
std::vector<MouseReport> runLockstep(Device& device, double endS) {
  std::vector<MouseReport> reports;
  MouseReport buffer[16];
  for (int ms = 1; ms <= static_cast<int>(endS * 1000.0 + 0.5); ++ms) {
    const double timeS = ms * 0.001;
    device.pushForceFrame({timeS - 0.001, 0.14f + 0.3f * static_cast<float>((ms / 100) % 2)});
    device.pump(timeS);
    int n = 0;
    while ((n = device.popReports(buffer, 16)) > 0) reports.insert(reports.end(), buffer, buffer + n);
  }
  return reports;
}
}  // namespace

TEST_CASE("record then replay gives identical reports", "[record]") {
  const std::string path = outputPath("record-replay.kfsession");
  DeviceSpec spec;
  spec.countMm = 0.0254;  // not the default: the header must carry it
  SimParams params;
  params.reportJitterS = 0.0007;
  params.dropProbability = 0.05;
  params.clockDriftPpm = -30.0;
  std::string error;
  auto recorded = openSimDevice(spec, params, HandScript::speeds({{120.0, 0.6}, {-400.0, 0.4}}), true, &error);
  REQUIRE(recorded);
  REQUIRE(recorded->startRecording(path, error));
  const auto original = runLockstep(*recorded, 1.0);
  recorded->close();
  REQUIRE(original.size() > 100);

  SessionData session;
  REQUIRE(readSessionFile(path, DeviceSpec{}, session, error));
  CHECK(session.spec.countMm == 0.0254);
  CHECK(session.reports.size() == original.size());
  CHECK(session.frames.size() == 1000);
  CHECK(session.frames[150].commandedForceN == Approx(0.44f));
  REQUIRE(session.offs.size() == 1);
  CHECK(session.offs[0].cause == "close");

  auto replayed = openReplayDevice(path, DeviceSpec{}, true, error);
  REQUIRE(replayed);
  CHECK(replayed->spec().countMm == 0.0254);
  const auto again = runLockstep(*replayed, 1.0);
  REQUIRE(again.size() == original.size());
  bool allSame = true;
  for (size_t i = 0; i < again.size(); ++i) allSame = allSame && sameReport(again[i], original[i]);
  CHECK(allSame);
  // Force commands go to the counting sink.
  auto& sink = dynamic_cast<CountingForceSink&>(replayed->forceBackend());
  CHECK(sink.commands() == 1000);
  CHECK(replayed->telemetry().frames == 1000);
  replayed->close();
  CHECK(sink.driveOffs() == 1);
}

TEST_CASE("session files with damage give clear errors", "[record]") {
  const std::string path = outputPath("damaged.kfsession");
  DeviceSpec spec;
  SessionData session;
  std::string error;
  auto write = [&](const char* text) { std::ofstream(path) << text; };

  write("kf-session 2 countMm=0.02\n");
  CHECK_FALSE(readSessionFile(path, spec, session, error));
  CHECK(error.find("version") != std::string::npos);

  write("kf-session 1 countMm=0.02\nR 0.1 0.1 3\n");
  CHECK_FALSE(readSessionFile(path, spec, session, error));
  CHECK(error.find(":2:") != std::string::npos);

  write(
      "kf-session 1 countMm=0.02 futureField=3\n# comment\nR 0.1 0.1 3 -4 1 0\nF 0.1 0.09 nan "
      "0.14\nO 0.2\n");
  REQUIRE(readSessionFile(path, spec, session, error));
  CHECK(session.spec.countMm == 0.02);
  REQUIRE(session.reports.size() == 1);
  CHECK(session.reports[0].report.dyCounts == -4);
  REQUIRE(session.frames.size() == 1);
  CHECK(std::isnan(session.frames[0].frame.forceN));
  REQUIRE(session.offs.size() == 1);
  CHECK(session.offs[0].cause.empty());  // written before off records said why: still read

  write("kf-session 1 countMm=0.02\nO 0.2 stop now\n");
  CHECK_FALSE(readSessionFile(path, spec, session, error));
  CHECK(error.find(":2:") != std::string::npos);

  std::string replayError;
  CHECK_FALSE(openReplayDevice(outputPath("no-such-file"), spec, true, replayError));
  CHECK_FALSE(replayError.empty());
}

TEST_CASE("an off record says why the magnet went off: stop, watchdog, quit, close", "[record]") {
  // The realtime test of the orderly stops (tests/realtime/test_orderly_off.py) tells the stop's
  // off from a watchdog trip earlier in the scene by this word.
  const std::string path = outputPath("off-causes.kfsession");
  std::string error;
  auto device = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::none(), true, &error);
  REQUIRE(device);
  REQUIRE(device->startRecording(path, error));
  int ms = 0;
  auto frames = [&](int count) {
    for (int i = 0; i < count; ++i, ++ms) {
      device->pushForceFrame({ms * 0.001, 1.0f});
      device->pump((ms + 1) * 0.001);
    }
  };
  auto silence = [&](double seconds) {
    for (const int end = ms + static_cast<int>(seconds * 1000.0); ms < end; ++ms) device->pump((ms + 1) * 0.001);
  };
  frames(100);
  device->requestOff();  // the last FrictionOut of the slot went away
  silence(0.05);
  frames(100);
  silence(2.0 * DeviceSpec{}.watchdogS + 0.01);  // frames stop without a stop
  frames(100);
  device->haltInOrder();  // the server's /quit
  device->close();

  SessionData session;
  REQUIRE(readSessionFile(path, DeviceSpec{}, session, error));
  std::vector<std::string> causes;
  for (const RecordedOff& off : session.offs) causes.push_back(off.cause);
  CHECK(causes == std::vector<std::string>{"stop", "watchdog", "quit", "close"});
  REQUIRE(session.offs.size() == 4);
  CHECK(session.offs[0].hostTimeS == Approx(0.1));
  CHECK(session.offs[1].hostTimeS > 0.25);
}
