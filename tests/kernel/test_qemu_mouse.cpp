// QEMU's emulated USB mouse on an xHCI controller, moved from the host through QMP: the real
// xhci_hcd, usbhid, hid-generic, hidraw and evdev between QEMU's reports and our two backends.
#include <fcntl.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <thread>

#include "guest/GuestSystem.hpp"
#include "guest/QemuInput.hpp"
#include "guest/ReportTally.hpp"
#include "guest/StallingIo.hpp"
#include "mouse/EvdevMouseBackend.hpp"
#include "mouse/HidapiMouseBackend.hpp"

using namespace kf;
using namespace kf::guest;

namespace {

// QEMU's USB mouse (hw/usb/dev-hid.c): vendor 0627, product 0001.
const std::string kQemuMouse = "0627:0001";

void pause(int ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); }

// Both backends on QEMU's mouse at once (hidraw and evdev are separate readers of one device).
struct BothBackends {
  std::unique_ptr<EvdevMouseBackend> evdev;
  std::unique_ptr<HidapiMouseBackend> hidapi;
  ReportTally evdevTally, hidapiTally;

  BothBackends(std::shared_ptr<EvdevApi> evdevApi, std::shared_ptr<HidApi> hidApi) {
    std::string error;
    evdev = EvdevMouseBackend::open(std::move(evdevApi), kQemuMouse, false, error);
    INFO(error);
    REQUIRE(evdev);
    hidapi = HidapiMouseBackend::open(std::move(hidApi), kQemuMouse, error);
    INFO(error);
    REQUIRE(hidapi);
  }
  // Counting starts again here, the buttons as they are.
  void restart(uint32_t buttons) {
    evdevTally = hidapiTally = ReportTally{};
    evdevTally.buttons = hidapiTally.buttons = buttons;
  }
  void drain() {
    evdevTally.drain(*evdev);
    hidapiTally.drain(*hidapi);
  }
  // Until both have read `dx`, `dy` in total and their buttons are `buttons` (a hang guard of 10 s).
  bool reach(int64_t dx, int64_t dy, uint32_t buttons) {
    return waitUntil(
        [&] {
          drain();
          for (const ReportTally* t : {&evdevTally, &hidapiTally})
            if (t->dxCounts != dx || t->dyCounts != dy || t->buttons != buttons) return false;
          return true;
        },
        10.0);
  }
};

// A scripted hand: moves of every size (300 counts: three reports, QEMU's reports hold 127),
// both signs, the three buttons pressed and released while moving and still, the wheel.
struct Step {
  int dx = 0, dy = 0;
  const char* button = nullptr;
  bool down = false;
};
const Step kScript[] = {
    {5, 0},
    {0, -7},
    {12, 9},
    {-3, 4},
    {0, 0, "left", true},
    {20, -20},
    {300, 0},
    {0, 0, "left", false},
    {0, 0, "wheel-up", true},
    {0, 0, "wheel-up", false},
    {-250, 130},
    {0, 0, "right", true},
    {1, 1},
    {0, 0, "middle", true},
    {-1, -1},
    {0, 0, "right", false},
    {0, 0, "middle", false},
    {0, 0, "wheel-down", true},
    {0, 0, "wheel-down", false},
    {7, -600},
    {1, 0},
    {0, 1},
    {-1, 0},
    {0, -1},
};

uint32_t buttonBit(const std::string& button) {
  return button == "left" ? 1u : button == "right" ? 2u : button == "middle" ? 4u : 0u;  // wheel: none
}

}  // namespace

TEST_CASE("QEMU's USB mouse: evdev and hidapi each read the counts and buttons QMP injected", "[kernel][qemu]") {
  BothBackends both(realEvdevApi(), realHidApi());
  pause(100);
  both.drain();
  both.restart(0);

  int64_t dx = 0, dy = 0;
  uint32_t buttons = 0;
  std::vector<uint32_t> buttonSteps;
  for (const Step& step : kScript) {
    if (step.button) {
      qemuButton(step.button, step.down);
      const uint32_t bit = buttonBit(step.button);
      if (bit) {
        buttons = step.down ? buttons | bit : buttons & ~bit;
        buttonSteps.push_back(buttons);
        // Each press or release reaches both before the next step: QEMU would fold button
        // changes its 16-event queue cannot hold, and this test is about our readers.
        REQUIRE(both.reach(dx, dy, buttons));
      }
    } else {
      qemuMove(step.dx, step.dy);
      dx += step.dx;
      dy += step.dy;
    }
    pause(5);
  }
  REQUIRE(both.reach(dx, dy, buttons));
  pause(200);  // nothing more may come
  both.drain();
  reportFigure("qemu mouse", "injected dx " + std::to_string(dx) + ", dy " + std::to_string(dy) + ", " +
                                 std::to_string(buttonSteps.size()) + " button changes; evdev read " +
                                 both.evdevTally.summary() + "; hidapi read " + both.hidapiTally.summary());
  for (const ReportTally* tally : {&both.evdevTally, &both.hidapiTally}) {
    CHECK(tally->dxCounts == dx);
    CHECK(tally->dyCounts == dy);
    CHECK(tally->buttonSteps == buttonSteps);
    CHECK(tally->afterLoss == 0);
  }
  CHECK(both.evdev->counters().lossEvents == 0);
  CHECK(both.hidapi->counters().lossEvents == 0);
  CHECK(both.evdev->hasKernelTimestamps());
}

TEST_CASE("a stalled reader: the kernel drops reports, the loss is reported, reading recovers", "[kernel][qemu]") {
  auto stall = std::make_shared<Stall>();
  BothBackends both(std::make_shared<StallingEvdevApi>(stall), std::make_shared<StallingHidApi>(stall));
  pause(100);
  both.drain();
  both.restart(0);

  // Both readers held at their next read while 150 reports come: 450 events for evdev (REL_X,
  // REL_Y, SYN_REPORT each), far more than its buffer for a mouse holds (a power of two of a few
  // hundred at most), and more than hidraw's ring of 63 reports. The left press comes early, so
  // the events after it overflow evdev's buffer and drop it.
  stall->on = true;
  REQUIRE(waitUntil([&] { return stall->held.load() == 2; }, 5.0));
  int64_t dx = 0, dy = 0;
  for (int i = 0; i < 150; ++i) {
    if (i == 5) qemuButton("left", true);
    qemuMove(1, -1);
    dx += 1;
    dy -= 1;
    pause(3);
  }
  pause(300);  // the guest has taken every report into the kernel's queues
  stall->on = false;

  // The drain after the stall: what the kernel kept, then the losses it reported.
  REQUIRE(
      waitUntil([&] { return both.evdev->counters().lossEvents > 0 && both.hidapi->counters().lossEvents > 0; }, 10.0));
  pause(300);
  both.drain();
  const ReportTally evdevStall = both.evdevTally, hidapiStall = both.hidapiTally;
  reportFigure("stall", "injected 150 reports (dx " + std::to_string(dx) + ", dy " + std::to_string(dy) +
                            ") with the readers held; evdev read " + evdevStall.summary() + ", losses " +
                            std::to_string(both.evdev->counters().lossEvents) + "; hidapi read " +
                            hidapiStall.summary() + ", losses " + std::to_string(both.hidapi->counters().lossEvents) +
                            " (estimated)");

  // evdev: the kernel said SYN_DROPPED; the buttons were read back from it (the press itself was
  // among the dropped events), the next report flagged.
  CHECK(both.evdev->counters().lossEvents >= 1);
  CHECK(evdevStall.afterLoss >= 1);
  CHECK(evdevStall.buttons == 1u);
  CHECK(evdevStall.dxCounts < dx);
  // hidraw: the ring kept the first 63 reports and dropped the rest, silently; a read that found
  // it full counted a loss (an estimate) and flagged the next report.
  CHECK(hidapiStall.reports == static_cast<uint64_t>(HidapiMouseBackend::kKernelQueueReports));
  CHECK(both.hidapi->counters().lossEvents >= 1);
  CHECK(both.hidapi->counters().lossesEstimated);
  CHECK(hidapiStall.buttons == 1u);
  CHECK(hidapiStall.dxCounts < dx);

  // Recovered: what comes after is read whole by both.
  both.restart(1);
  qemuButton("left", false);
  for (int i = 0; i < 40; ++i) {
    qemuMove(2, 3);
    pause(5);
  }
  REQUIRE(both.reach(80, 120, 0));
  CHECK(both.evdevTally.buttonSteps == std::vector<uint32_t>{0u});
  CHECK(both.hidapiTally.buttonSteps == std::vector<uint32_t>{0u});
  CHECK(both.evdevTally.afterLoss == 0);
}
