// Unplug and replug as a user does it, through the real kernel: QEMU's USB mouse removed and
// plugged back into its port by QMP (device_del, device_add) beside its twin (the same make in
// another port), and uhid devices destroyed and created again beside theirs. The reader sees the
// unplug, a re-open finds the same mouse and never the twin.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <functional>
#include <thread>

#include "guest/GuestSystem.hpp"
#include "guest/HostHook.hpp"
#include "guest/QemuInput.hpp"
#include "guest/ReportTally.hpp"
#include "guest/UhidDevice.hpp"
#include "mouse/EvdevMouseBackend.hpp"
#include "mouse/HidapiMouseBackend.hpp"

using namespace kf;
using namespace kf::guest;

namespace {

void pause(int ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); }

size_t qemuMiceListed(const std::shared_ptr<EvdevApi>& api) {
  std::vector<MouseInfo> mice;
  std::string error;
  api->enumerateMice(mice, error);
  return static_cast<size_t>(
      std::count_if(mice.begin(), mice.end(), [](const MouseInfo& m) { return m.vendorId == 0x0627; }));
}

bool unplugged(const RealMouseBackend& backend) { return backend.state() == MouseState::kUnplugged; }

// Seconds from `start` until `done` (a hang guard of 10 s), -1 if it never was.
double secondsUntil(std::chrono::steady_clock::time_point start, const std::function<bool()>& done) {
  if (!waitUntil(done, 10.0)) return -1.0;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A move the reopened readers must read whole (QEMU gives it to the mouse plugged in last).
void moveAndRead(RealMouseBackend& evdev, RealMouseBackend& hidapi) {
  ReportTally e, h;
  for (int i = 0; i < 10; ++i) {
    qemuMove(3, -2);
    pause(5);
  }
  CHECK(waitUntil(
      [&] {
        e.drain(evdev);
        h.drain(hidapi);
        return e.dxCounts == 30 && e.dyCounts == -20 && h.dxCounts == 30 && h.dyCounts == -20;
      },
      10.0));
  INFO("evdev " << e.summary() << "; hidapi " << h.summary());
  CHECK(e.dxCounts == 30);
  CHECK(h.dxCounts == 30);
}

}  // namespace

TEST_CASE("QMP unplug and replug: the reader sees the unplug, re-opens the same mouse, never its twin",
          "[kernel][qemu][replug]") {
  auto evdevApi = realEvdevApi();
  HostHook& hook = HostHook::instance();
  // The twin: QEMU's USB mouse again (same ids, its own serial) in port 2.
  hook.qmpOrThrow(R"({"execute": "device_add", "arguments": {"driver": "usb-mouse", "bus": "xhci.0", "port": "2",
                      "id": "twin"}})");
  REQUIRE(waitUntil([&] { return qemuMiceListed(evdevApi) == 2; }, 20.0));
  udevSettle();

  // "first": the mouse in port 1 (ordered by port), as a user would open it.
  std::string error;
  auto evdev = EvdevMouseBackend::open(evdevApi, "first", false, error);
  INFO(error);
  REQUIRE(evdev);
  auto hidapi = HidapiMouseBackend::open(realHidApi(), "first", error);
  INFO(error);
  REQUIRE(hidapi);
  const MouseInfo evdevBefore = evdev->info(), hidapiBefore = hidapi->info();
  REQUIRE(evdevBefore.busPath.find("/1-1:1.0/") != std::string::npos);
  REQUIRE(hidapiBefore.busPath.find("/1-1:1.0/") != std::string::npos);

  const auto unplugAt = std::chrono::steady_clock::now();
  hook.qmpOrThrow(R"({"execute": "device_del", "arguments": {"id": "mouse1"}})");
  const double evdevUnplugS = secondsUntil(unplugAt, [&] { return unplugged(*evdev); });
  const double hidapiUnplugS = secondsUntil(unplugAt, [&] { return unplugged(*hidapi); });
  CHECK(evdevUnplugS >= 0);
  CHECK(hidapiUnplugS >= 0);
  REQUIRE(waitUntil([&] { return qemuMiceListed(evdevApi) == 1; }, 20.0));

  // Away: a re-open finds only the twin, which it must not take.
  evdev->requestReopen();
  hidapi->requestReopen();
  pause(300);
  CHECK(unplugged(*evdev));
  CHECK(unplugged(*hidapi));
  const std::string evdevRefusal = evdev->lastError(), hidapiRefusal = hidapi->lastError();
  CHECK(evdevRefusal.find("is plugged in") != std::string::npos);
  CHECK(hidapiRefusal.find("is plugged in") != std::string::npos);
  CHECK(evdev->counters().reopens == 0);

  // Back in its port: the same mouse (port, serial) under new node numbers, read again.
  hook.qmpOrThrow(R"({"execute": "device_add", "arguments": {"driver": "usb-mouse", "bus": "xhci.0", "port": "1",
                      "id": "mouse1"}})");
  REQUIRE(waitUntil([&] { return qemuMiceListed(evdevApi) == 2; }, 20.0));
  udevSettle();
  evdev->requestReopen();
  hidapi->requestReopen();
  CHECK(waitUntil([&] { return evdev->state() == MouseState::kRunning && hidapi->state() == MouseState::kRunning; },
                  10.0));
  const MouseInfo evdevAfter = evdev->info(), hidapiAfter = hidapi->info();
  CHECK(evdevAfter.busPath == evdevBefore.busPath);
  CHECK(evdevAfter.serial == evdevBefore.serial);
  CHECK(hidapiAfter.busPath == hidapiBefore.busPath);
  CHECK(hidapiAfter.serial == hidapiBefore.serial);
  CHECK(evdev->counters().reopens == 1);
  CHECK(hidapi->counters().reopens == 1);
  moveAndRead(*evdev, *hidapi);
  reportFigure("qmp replug", "unplug seen (from the device_del request) within " + std::to_string(evdevUnplugS * 1e3) +
                                 " ms (evdev), " + std::to_string(hidapiUnplugS * 1e3) +
                                 " ms (hidapi); re-open with only the twin: " + evdevRefusal + " | " + hidapiRefusal +
                                 "; after the replug: evdev " + evdevBefore.path + " -> " + evdevAfter.path +
                                 ", hidapi " + hidapiBefore.path + " -> " + hidapiAfter.path + " at " +
                                 evdevAfter.busPath);

  evdev.reset();
  hidapi.reset();
  hook.qmpOrThrow(R"({"execute": "device_del", "arguments": {"id": "twin"}})");
  REQUIRE(waitUntil([&] { return qemuMiceListed(evdevApi) == 1; }, 20.0));
}

TEST_CASE("uhid destroy and create: the same mouse again by its serial, never its twin", "[kernel][uhid][replug]") {
  // A boot mouse (HID 1.11 appendix B) with report IDs... none: 3 buttons, X, Y.
  const std::vector<uint8_t> descriptor = {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x09, 0x01, 0xA1, 0x00, 0x05, 0x09, 0x19,
                                           0x01, 0x29, 0x03, 0x15, 0x00, 0x25, 0x01, 0x95, 0x03, 0x75, 0x01, 0x81, 0x02,
                                           0x95, 0x01, 0x75, 0x05, 0x81, 0x01, 0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x15,
                                           0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0xC0, 0xC0};
  const UhidIdentity mine{"KF guest wireless mouse", "AA:BB:CC:00:00:01", 0x03, 0x1209, 0x0040};
  UhidIdentity twinIdentity = mine;
  twinIdentity.uniq = "AA:BB:CC:00:00:02";
  auto device = std::make_unique<UhidDevice>(mine, descriptor);
  UhidDevice twin(twinIdentity, descriptor);
  const std::string selector = "1209:0040:" + mine.uniq;
  std::unique_ptr<EvdevMouseBackend> evdev;
  std::unique_ptr<HidapiMouseBackend> hidapi;
  REQUIRE(waitUntil(
      [&] {
        std::string ignored;
        if (!evdev) evdev = EvdevMouseBackend::open(realEvdevApi(), selector, false, ignored);
        if (!hidapi) hidapi = HidapiMouseBackend::open(realHidApi(), selector, ignored);
        return evdev && hidapi;
      },
      20.0));
  CHECK(evdev->info().serial == mine.uniq);
  CHECK(hidapi->info().serial == mine.uniq);

  device.reset();  // UHID_DESTROY: unplugged
  CHECK(waitUntil([&] { return unplugged(*evdev) && unplugged(*hidapi); }, 10.0));
  evdev->requestReopen();
  hidapi->requestReopen();
  pause(300);
  CHECK(unplugged(*evdev));  // the twin (other serial) is not it
  CHECK(unplugged(*hidapi));

  device = std::make_unique<UhidDevice>(mine, descriptor);
  REQUIRE(waitUntil(
      [&] {
        evdev->requestReopen();
        hidapi->requestReopen();
        pause(50);
        return evdev->state() == MouseState::kRunning && hidapi->state() == MouseState::kRunning;
      },
      20.0));
  CHECK(evdev->info().serial == mine.uniq);
  CHECK(hidapi->info().serial == mine.uniq);
  ReportTally e, h;
  const uint8_t fromMine[] = {0x01, 5, 0xFD}, fromTwin[] = {0x00, 100, 100};
  for (int i = 0; i < 10; ++i) {
    device->send(fromMine, sizeof(fromMine));
    twin.send(fromTwin, sizeof(fromTwin));
    pause(5);
  }
  CHECK(waitUntil(
      [&] {
        e.drain(*evdev);
        h.drain(*hidapi);
        return e.dxCounts == 50 && h.dxCounts == 50;
      },
      10.0));
  pause(100);
  e.drain(*evdev);
  h.drain(*hidapi);
  CHECK(e.dxCounts == 50);
  CHECK(e.dyCounts == -30);
  CHECK(e.buttons == 1u);
  CHECK(h.dxCounts == 50);
  CHECK(h.dyCounts == -30);
  reportFigure("uhid replug", "re-open with only the twin: " + evdev->lastError() + "; after re-creating it: evdev " +
                                  e.summary() + ", hidapi " + h.summary() + " (the twin moved 1000, 1000 meanwhile)");
}
