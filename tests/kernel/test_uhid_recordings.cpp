// Recorded and synthetic mice (tests/data/hid) made real through uhid: the kernel parses each
// report descriptor, hid-generic binds it, and the reports are written at their recorded times
// (up to 8 kHz). Both backends must give the trajectory the tests take from the file directly
// (loadReplayReports: our decoder on the file), report for report; for evdev the kernel's own
// hid-input decodes the reports, so it is the referee of our decoder.
#include <catch2/catch.hpp>
#include <chrono>
#include <sstream>
#include <thread>

#include "core/spec/DeviceSpec.hpp"
#include "guest/GuestSystem.hpp"
#include "guest/ReportTally.hpp"
#include "guest/UhidDevice.hpp"
#include "mouse/EvdevMouseBackend.hpp"
#include "mouse/HidapiMouseBackend.hpp"
#include "recordings/HidRecorderFile.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;
using namespace kf::guest;

namespace {

struct Motion {
  int32_t dx, dy;
  uint32_t buttons;
  bool operator==(const Motion& o) const { return dx == o.dx && dy == o.dy && buttons == o.buttons; }
};

std::ostream& operator<<(std::ostream& out, const Motion& m) {
  return out << "(" << m.dx << ", " << m.dy << ", buttons " << m.buttons << ")";
}

std::vector<Motion> motions(const std::vector<MouseReport>& reports) {
  std::vector<Motion> out;
  for (const MouseReport& r : reports) out.push_back({r.dxCounts, r.dyCounts, r.buttons});
  return out;
}

// What evdev hands on of them: the kernel passes no event for a zero delta or an unchanged
// button, so a report that changes nothing (a wheel step) makes no packet.
std::vector<Motion> withoutNoOps(const std::vector<Motion>& reports) {
  std::vector<Motion> out;
  uint32_t buttons = 0;
  for (const Motion& m : reports) {
    if (m.dx != 0 || m.dy != 0 || m.buttons != buttons) out.push_back(m);
    buttons = m.buttons;
  }
  return out;
}

// The first index where two sequences differ, for the message.
std::string firstDifference(const std::vector<Motion>& got, const std::vector<Motion>& want) {
  for (size_t i = 0; i < std::min(got.size(), want.size()); ++i)
    if (!(got[i] == want[i])) {
      std::ostringstream text;
      text << "report " << i << ": got " << got[i] << ", the file gives " << want[i];
      return text.str();
    }
  return got.size() == want.size() ? "none"
                                   : "lengths " + std::to_string(got.size()) + " and " + std::to_string(want.size());
}

struct Played {
  std::vector<Motion> expected;  // the file's mouse reports, as our decoder reads the file
  size_t otherReports = 0;       // input reports that are no mouse report (vendor, consumer keys)
  ReportTally evdev, hidapi;
  uint64_t hidapiMalformed = 0, evdevLosses = 0, hidapiLosses = 0;
  double lateMaxS = 0.0, playedS = 0.0;
};

// Plays the recording on a uhid device with the ids 1209:`product`; both backends read it.
Played play(const std::string& file, uint16_t product) {
  const std::string path = std::string(KF_HID_DATA_DIR) + "/" + file;
  Played out;
  HidRecording recording;
  std::string error;
  REQUIRE(readHidRecorderFile(path, recording, error));
  DeviceSpec spec;
  std::vector<TimedReport> fromFile;
  REQUIRE(loadReplayReports(path, spec, fromFile, error, &out.otherReports));
  for (const TimedReport& t : fromFile)
    out.expected.push_back({t.report.dxCounts, t.report.dyCounts, t.report.buttons});

  char ids[16];
  std::snprintf(ids, sizeof(ids), "1209:%04x", product);
  UhidDevice device({recording.name, "kf-" + file, 0x03, 0x1209, product}, recording.descriptor);
  std::unique_ptr<EvdevMouseBackend> evdev;
  std::unique_ptr<HidapiMouseBackend> hidapi;
  // The nodes come once hid-generic has bound the device and udev has run.
  REQUIRE(waitUntil(
      [&] {
        std::string ignored;
        if (!evdev) evdev = EvdevMouseBackend::open(realEvdevApi(), ids, false, ignored);
        if (!hidapi) hidapi = HidapiMouseBackend::open(realHidApi(), ids, ignored);
        return evdev && hidapi;
      },
      20.0));

  const auto start = std::chrono::steady_clock::now() + std::chrono::milliseconds(50);
  const double firstS = recording.events.empty() ? 0.0 : recording.events.front().timeS;
  for (const HidRecordedEvent& event : recording.events) {
    const auto due = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                 std::chrono::duration<double>(event.timeS - firstS));
    std::this_thread::sleep_until(due);
    out.lateMaxS =
        std::max(out.lateMaxS, std::chrono::duration<double>(std::chrono::steady_clock::now() - due).count());
    device.send(event.bytes);
  }
  out.playedS = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const size_t evdevWant = withoutNoOps(out.expected).size();
  waitUntil(
      [&] {
        out.evdev.drain(*evdev);
        out.hidapi.drain(*hidapi);
        return out.hidapi.reports >= out.expected.size() && out.evdev.reports >= evdevWant;
      },
      20.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // nothing more may come
  out.evdev.drain(*evdev);
  out.hidapi.drain(*hidapi);
  out.hidapiMalformed = hidapi->counters().malformed;
  out.evdevLosses = evdev->counters().lossEvents;
  out.hidapiLosses = hidapi->counters().lossEvents;
  reportFigure("uhid " + file, std::to_string(recording.events.size()) + " reports written over " +
                                   std::to_string(out.playedS) + " s (recorded " +
                                   std::to_string(recording.events.back().timeS - firstS) + " s, latest write " +
                                   std::to_string(out.lateMaxS * 1e3) + " ms late); evdev read " + out.evdev.summary() +
                                   "; hidapi read " + out.hidapi.summary() + ", losses " +
                                   std::to_string(out.evdevLosses) + " / " + std::to_string(out.hidapiLosses));
  return out;
}

void checkBoth(const Played& played) {
  const std::vector<Motion> evdevGot = motions(played.evdev.all), hidapiGot = motions(played.hidapi.all);
  const std::vector<Motion> evdevWant = withoutNoOps(played.expected);
  INFO("evdev: first difference " << firstDifference(evdevGot, evdevWant));
  CHECK(evdevGot == evdevWant);
  INFO("hidapi: first difference " << firstDifference(hidapiGot, played.expected));
  CHECK(hidapiGot == played.expected);
  CHECK(played.hidapiMalformed == played.otherReports);  // the vendor or consumer reports, skipped
  CHECK(played.evdevLosses == 0);
  CHECK(played.hidapiLosses == 0);
}

}  // namespace

TEST_CASE("uhid: a real mouse's recording (Genius, 16-bit, 500 Hz) reads as the file gives it", "[kernel][uhid]") {
  checkBoth(play("genius-gila-gaming-mouse-0458-0138.hid", 0x0010));
}

TEST_CASE("uhid: a 125 Hz boot-like mouse, saturated reports included, reads as the file gives it", "[kernel][uhid]") {
  const Played played = play("synthetic-125hz-8bit-boot.hid", 0x0011);
  checkBoth(played);
  CHECK(played.evdev.saturated == 24);  // at the descriptor's limit, from sysfs's descriptor
  CHECK(played.hidapi.saturated == 24);
}

TEST_CASE("uhid: a 1 kHz mouse with 12-bit fields and a vendor collection reads as the file gives it",
          "[kernel][uhid]") {
  checkBoth(play("synthetic-1khz-12bit-gaming.hid", 0x0012));
}

TEST_CASE("uhid: an 8 kHz mouse with 16-bit fields and consumer keys reads as the file gives it", "[kernel][uhid]") {
  checkBoth(play("synthetic-8khz-16bit-gaming.hid", 0x0013));
}

TEST_CASE("uhid: a mouse that sends its buttons in a report of their own (Xiaomi layout): its presses are read",
          "[kernel][uhid]") {
  const Played played = play("synthetic-250hz-split-buttons.hid", 0x0014);
  checkBoth(played);
  // The file's presses (tests/data/hid/README.md): left, left again, right; each released.
  const std::vector<uint32_t> presses{1, 0, 1, 0, 2, 0};
  CHECK(played.evdev.buttonSteps == presses);
  CHECK(played.hidapi.buttonSteps == presses);
}
