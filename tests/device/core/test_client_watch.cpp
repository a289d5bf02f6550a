// The client watch (Device::watchClient, kfHeartbeat): a realtime device pumped on the test's own
// clock (DeviceOptions::externalPump), frames of 0.8 N every ms as an orphaned FrictionOut keeps
// sending them, and a mouse reporting at 125 Hz. Exact times: the pumps are the clock.
#include <catch2/catch.hpp>
#include <memory>
#include <string>
#include <vector>

#include "ForcePathSupport.hpp"
#include "core/Device.hpp"
#include "core/files/SessionFile.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;
using kf::test::TimelineSink;

namespace {

constexpr double kForceN = 0.8;

std::vector<TimedReport> reportsAt125Hz(double seconds) {
  std::vector<TimedReport> reports;
  for (int i = 0; i * 0.008 < seconds; ++i) {
    TimedReport timed;
    timed.hostTimeS = i * 0.008;
    timed.report.deviceTimeS = timed.hostTimeS;
    timed.report.dxCounts = 1;
    reports.push_back(timed);
  }
  return reports;
}

struct WatchedDevice {
  static DeviceOptions externalPump() {
    DeviceOptions options;
    options.externalPump = true;
    return options;
  }
  std::shared_ptr<TimelineSink> sink = std::make_shared<TimelineSink>();
  Device device{DeviceSpec{}, std::make_shared<ReplayBackend>(reportsAt125Hz(10.0)), sink, false, externalPump()};
  int ms = 0;
  double pumpS = 0.0;  // the clock: the last pump's time (drive-offs carry none of their own)
  WatchedDevice() {
    sink->setClock([this] { return pumpS; });
    device.start();
  }
  // One ms: a frame of kForceN sent, then the pump at the ms's end.
  void run(double seconds) {
    for (const int end = ms + static_cast<int>(seconds * 1000.0 + 0.5); ms < end; ++ms) {
      device.pushForceFrame({ms * 0.001, static_cast<float>(kForceN)});
      pumpS = (ms + 1) * 0.001;
      device.pump(pumpS);
    }
  }
  double nowS() const { return ms * 0.001; }
};

}  // namespace

TEST_CASE("a silent watched client: the magnet off after its timeout, nothing recorded after", "[client]") {
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/client-watch.kfsession";
  WatchedDevice watched;
  std::string error;
  REQUIRE(watched.device.startRecording(path, error));
  watched.device.watchClient(0.5);
  // Heartbeats every 0.25 s for 1 s: the force is driven all along.
  for (int beat = 0; beat < 4; ++beat) {
    watched.run(0.25);
    watched.device.heartbeat();
  }
  CHECK(watched.device.commandedForceN() == Approx(kForceN));
  CHECK_FALSE(watched.device.clientSilent());
  const double lastBeatS = watched.nowS();
  // The client falls silent; its synths go on sending frames.
  watched.run(1.0);
  CHECK(watched.device.clientSilent());
  CHECK(watched.device.commandedForceN() == Approx(DeviceSpec{}.minForceN));  // the magnet off: the puck's own friction
  // The off came at the first pump past the timeout, and nothing was driven after it.
  std::vector<TimelineSink::Event> events = watched.sink->events();
  double offS = -1.0;
  for (const TimelineSink::Event& e : events)
    if (e.off && e.timeS > lastBeatS) {
      offS = e.timeS;
      break;
    }
  CHECK(offS == Approx(lastBeatS + 0.501).margin(1e-9));
  for (const TimelineSink::Event& e : watched.sink->commands()) CHECK(e.timeS < offS);

  // A heartbeat brings the force back.
  watched.device.heartbeat();
  watched.run(0.1);
  CHECK_FALSE(watched.device.clientSilent());
  CHECK(watched.device.commandedForceN() == Approx(kForceN));
  // No watch (the live coder's default): silence changes nothing.
  watched.device.watchClient(0.0);
  watched.run(1.0);
  CHECK(watched.device.commandedForceN() == Approx(kForceN));
  watched.device.close();

  SessionData session;
  REQUIRE(readSessionFile(path, DeviceSpec{}, session, error));
  std::vector<std::string> causes;
  for (const RecordedOff& off : session.offs) causes.push_back(off.cause);
  CHECK(causes == std::vector<std::string>{"client", "close"});
  REQUIRE(session.offs.size() == 2);
  CHECK(session.offs[0].hostTimeS == Approx(offS).margin(1e-9));
  // While silent (from the off to the heartbeat at 2.0 s), no report and no frame was recorded.
  for (const TimedReport& r : session.reports) CHECK_FALSE((r.hostTimeS > offS && r.hostTimeS <= 2.0));
  for (const RecordedFrame& f : session.frames) CHECK_FALSE((f.hostTimeS > offS && f.hostTimeS <= 2.0));
  CHECK(session.reports.size() > 300);  // and before and after it, at 125 Hz
}
