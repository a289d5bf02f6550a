// The board driver's life cycle against the emulated bus: the interface checked before a
// device with the (shared test) IDs is touched, the protocol version, CLEAR_ERRORS on open and
// before ARM, ARM through the slew limiter (also when its reply is slow), control requests on
// the event thread, and libusb's transfer rules with callbacks that arrive late or never
// (EmulatedUsb counts every breach).
#include <catch2/catch.hpp>
#include <chrono>
#include <thread>

#include "BoardTestSupport.hpp"
#include "board/EmulatedUsb.hpp"
#include "board/UsbBoardBackend.hpp"
#include "core/Device.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;
using namespace kf::board;
using kf::test::armAlone;
using kf::test::openBoard;
using kf::test::waitFor;
using namespace std::chrono_literals;

namespace {

void checkNoBreach(EmulatedUsb& bus) {
  CHECK(bus.closesInFlight() == 0);
  CHECK(bus.resubmitsInFlight() == 0);
  CHECK(bus.haltsInFlight() == 0);
  CHECK(bus.eventsOffThread() == 0);
}

}  // namespace

TEST_CASE("board identity: a stranger with the test IDs is never touched", "[board]") {
  const usb::InterfaceIdentity board{kInterfaceNumber, kInterfaceClass, kInterfaceSubclass, kInterfaceProtocol};
  CHECK(usb::interfaceMismatch(&board, board).empty());
  const usb::InterfaceIdentity keyboard{0, 0x03, 0x01, 0x01};
  CHECK(usb::interfaceMismatch(&keyboard, board) == "interface 0 is class 03/01/01, not ff/4b/01");
  CHECK_FALSE(usb::interfaceMismatch(nullptr, board).empty());
  for (const usb::InterfaceIdentity& other :
       {usb::InterfaceIdentity{0, 0xFF, 0x00, 0x01}, usb::InterfaceIdentity{0, 0xFF, 0x4B, 0x02}})
    CHECK_FALSE(usb::interfaceMismatch(&other, board).empty());  // subclass, protocol

  auto bus = EmulatedUsb::create();
  bus->addStranger(keyboard);
  auto backend = openBoard(bus);  // the board after it is found, the stranger left alone
  CHECK(backend->telemetry().serial == "KF-EMU-0001");
  backend->close();
  bus->unplug();  // only the stranger is left
  UsbBoardBackend alone(bus->makePort());
  std::string error;
  CHECK_FALSE(alone.open(error));
  INFO(error);
  CHECK(error.find("no friction board found") != std::string::npos);
  CHECK(error.find("Left alone, not a board: bus 1 device 1: interface 0 is class 03/") != std::string::npos);
  CHECK(error.size() < 190);  // a /kfFail reason: 200 characters with "kfBoardOpen: "
  CHECK(bus->strangerTouches() == 0);
}

TEST_CASE("board version: a board of another protocol major is refused with what to do", "[board]") {
  auto bus = EmulatedUsb::create();
  bus->setProtocolMajor(1);
  UsbBoardBackend backend(bus->makePort());
  std::string error;
  CHECK_FALSE(backend.open(error));
  INFO(error);
  CHECK(error.find("speaks protocol 1.1, this host 2.x") != std::string::npos);
  CHECK(error.find("firmware") != std::string::npos);
  CHECK_FALSE(bus->isOpen());
  CHECK(bus->interfaceReleases() == 1);
}

TEST_CASE("board errors: open and arm clear them, a reset is reported once, a persisting fault refuses ARM",
          "[board]") {
  auto bus = EmulatedUsb::create();
  auto backend = openBoard(bus);
  BoardTelemetry t = backend->telemetry();
  CHECK(t.boardResets == 1);  // the enumeration, read and acknowledged by open
  CHECK((t.lastClear.before & kErrUsbReset) != 0);
  REQUIRE(waitFor([&] { return backend->telemetry().haveStatus; }));
  CHECK((backend->telemetry().status.errors & kErrUsbReset) == 0);  // not stuck

  bus->busReset();  // mid-session: the board disarms and says why
  REQUIRE(waitFor([&] {
    const BoardTelemetry now = backend->telemetry();
    return (now.status.errors & kErrUsbReset) != 0 && now.status.state == BoardState::kDisarmed;
  }));
  std::string error;
  REQUIRE(armAlone(*backend, error));  // CLEAR_ERRORS first: the reset counted, then cleared
  CHECK(backend->telemetry().boardResets == 2);
  REQUIRE(waitFor([&] { return backend->telemetry().status.state == BoardState::kArmed; }));
  CHECK((backend->telemetry().status.errors & kErrUsbReset) == 0);

  bus->overCurrent(/*persists=*/true);
  REQUIRE(waitFor([&] { return backend->telemetry().status.state == BoardState::kFault; }));
  CHECK_FALSE(backend->arm(error));
  CHECK(error.find("over current") != std::string::npos);
  CHECK(error.find("persists") != std::string::npos);
  CHECK(bus->state() == BoardState::kFault);
  bus->setOverCurrent(false);  // fixed: no power cycle needed
  REQUIRE(armAlone(*backend, error));
  CHECK(bus->state() == BoardState::kArmed);
  backend->close();
  checkNoBreach(*bus);
}

// A lockstep device whose board drive slews 0.1 N per 1 ms frame (13 frames from min to max):
// frames pushed are applied at once, so a test sees each frame's drive.
struct SlewedBoardDevice {
  DeviceSpec spec = [] {
    DeviceSpec s;
    s.maxForceSlewNPerS = 100.0;
    return s;
  }();
  std::shared_ptr<EmulatedUsb> bus = EmulatedUsb::create();
  std::shared_ptr<UsbBoardBackend> board = openBoard(bus);
  Device device{spec, std::make_shared<ReplayBackend>(std::vector<TimedReport>{}),
                std::make_shared<CountingForceSink>(), /*lockstep=*/true};
  double frameS = 0.0;

  SlewedBoardDevice() {
    REQUIRE(device.attachBoard(board) == nullptr);
    device.pump(0.0);  // lockstep: frames pushed from now on are applied at once
  }
  // Pushes the next frame's force; the drive the board was given for it.
  uint16_t frame(float forceN) {
    frameS += spec.forceFramePeriodS;
    device.pushForceFrame({frameS, forceN, frameS});
    return board->latestDrive();
  }
  // One frame's worth of slew in drive units (linear table): 0.1 N of 1.26 N, +1 for rounding.
  double maxStepDrive() const {
    return spec.maxForceSlewNPerS * spec.forceFramePeriodS / (spec.maxForceN - spec.minForceN) * kDriveFull + 1.0;
  }
};

TEST_CASE("board arm: the force starts from the minimum through the slew limiter", "[board]") {
  SlewedBoardDevice rig;
  const std::shared_ptr<EmulatedUsb>& bus = rig.bus;
  const std::shared_ptr<UsbBoardBackend>& board = rig.board;
  Device& device = rig.device;
  for (int i = 0; i < 40; ++i) rig.frame(1.4f);  // disarmed: the request has slewed up to the top
  REQUIRE(board->latestDrive() == kDriveFull);
  std::string error;
  REQUIRE(board->arm(error));
  CHECK(board->latestDrive() == 0);
  const uint64_t frames = bus->validFrames();
  REQUIRE(waitFor([&] { return bus->validFrames() > frames + 5; }));
  CHECK(bus->drive() == 0);  // no frame since ARM: the board is not driven to the old request
  const double maxStep = rig.maxStepDrive();
  uint16_t previous = 0;
  int steps = 0;
  while (previous < kDriveFull && steps < 100) {
    const uint16_t drive = rig.frame(1.4f);
    CHECK(drive - previous <= maxStep);
    CHECK(drive > previous);
    previous = drive;
    ++steps;
  }
  CHECK(steps == 13);  // 1.26 N at 0.1 N a frame
  REQUIRE(waitFor([&] { return bus->drive() == kDriveFull; }));
  device.close();
}

TEST_CASE("board transfers: close waits for callbacks that arrive late, whatever the timeout", "[board]") {
  auto bus = EmulatedUsb::create();
  BoardOptions options;
  options.transferTimeoutMs = 2000;  // set-points the board never takes stay in flight 2 s
  auto backend = openBoard(bus, options);
  std::string error;
  REQUIRE(armAlone(*backend, error));
  backend->commandDrive(0.0, 1.0f, 0.5f);
  REQUIRE(waitFor([&] { return bus->drive() == 32768; }));
  bus->timeOutNextOut(1000000);
  bus->delayCallbacks(0.6);  // longer than any fixed wait the driver had
  std::this_thread::sleep_for(10ms);
  backend->close();
  checkNoBreach(*bus);
  CHECK_FALSE(bus->isOpen());
  CHECK(bus->state() == BoardState::kDisarmed);
  CHECK_FALSE(backend->telemetry().transfersLeaked);
}

TEST_CASE("board transfers: an unplug drops the handle only after every late callback", "[board]") {
  auto bus = EmulatedUsb::create();
  BoardOptions options;
  options.reopenPeriodS = 0.05;
  auto backend = openBoard(bus, options);
  REQUIRE(waitFor([&] { return backend->telemetry().haveStatus && bus->validFrames() > 5; }));  // in flight
  // The status transfer reports the unplug at once; the set-points' callbacks come 0.6 s later.
  bus->delayCallbacks(0.6, kSetPointEndpoint);
  bus->unplug();
  REQUIRE(waitFor([&] { return !backend->telemetry().connected; }));
  bus->delayCallbacks(0.0);
  bus->replug();
  REQUIRE(waitFor([&] { return backend->telemetry().connected; }));
  CHECK(backend->telemetry().reopens == 1);
  backend->close();
  checkNoBreach(*bus);
}

TEST_CASE("board reopen: after an unplug the same board is opened again, not another in its place", "[board]") {
  auto bus = EmulatedUsb::create("KF-0001");
  BoardOptions options;
  options.reopenPeriodS = 0.02;
  auto backend = openBoard(bus, options);  // no serial asked: the first board, KF-0001
  bus->unplug();
  REQUIRE(waitFor([&] { return !backend->telemetry().connected; }));
  bus->replug("KF-0002");              // another board in its place: its table would be wrong
  std::this_thread::sleep_for(100ms);  // five reopen periods
  CHECK_FALSE(backend->telemetry().connected);
  CHECK(backend->telemetry().reopens == 0);
  bus->unplug();
  bus->replug("KF-0001");
  REQUIRE(waitFor([&] { return backend->telemetry().connected; }));
  CHECK(backend->telemetry().serial == "KF-0001");
  backend->close();
}

TEST_CASE("board control: ARM, DISARM and CLEAR_ERRORS are sent by the event thread", "[board]") {
  // Sent from the caller's thread while transfers are in flight, libusb would run their
  // callbacks there, beside the event thread that owns their state.
  auto bus = EmulatedUsb::create();
  auto backend = openBoard(bus);
  REQUIRE(waitFor([&] { return backend->telemetry().haveStatus && bus->validFrames() > 5; }));  // in flight
  std::string error;
  for (int i = 0; i < 3; ++i) {
    REQUIRE(armAlone(*backend, error));
    CHECK(bus->state() == BoardState::kArmed);
    REQUIRE(backend->disarm(error));
    CHECK(bus->state() == BoardState::kDisarmed);
  }
  CHECK(backend->telemetry().boardResets == 1);  // each CLEAR_ERRORS answered: the power-on one
  backend->close();
  checkNoBreach(*bus);
}

TEST_CASE("board arm: frames applied while the ARM's reply is on its way do not jump the drive", "[board]") {
  SlewedBoardDevice rig;
  const std::shared_ptr<EmulatedUsb>& bus = rig.bus;
  const std::shared_ptr<UsbBoardBackend>& board = rig.board;
  Device& device = rig.device;
  bus->holdArmReply(true);
  std::string error;
  bool armed = false;
  std::thread arming([&] { armed = board->arm(error); });
  REQUIRE(waitFor([&] { return bus->armsHeld() == 1; }));
  // 40 frames while ARM is in flight (on USB 1-3 ms, up to its 200 ms timeout): they take the
  // restart and ramp the request to the top while the set-points still carry 0.
  for (int i = 0; i < 40; ++i) rig.frame(1.4f);
  REQUIRE(board->latestDrive() == kDriveFull);
  bus->holdArmReply(false);
  arming.join();
  INFO(error);
  REQUIRE(armed);
  const uint64_t frames = bus->validFrames();
  REQUIRE(waitFor([&] { return bus->validFrames() > frames + 5; }));
  CHECK(bus->drive() == 0);  // no frame since ARM returned: not the ramp made before
  const double maxStep = rig.maxStepDrive();
  uint16_t previous = 0;
  int steps = 0;
  while (previous < kDriveFull && steps < 100) {
    const uint16_t drive = rig.frame(1.4f);
    CHECK(drive - previous <= maxStep);
    previous = drive;
    ++steps;
  }
  CHECK(steps == 13);  // up from the minimum again
  device.close();
}

TEST_CASE("board transfers: a callback that never comes back is given up once, open says restart", "[board]") {
  auto bus = EmulatedUsb::create();
  BoardOptions options;
  options.callbackWaitS = 0.05;  // 10 s in use
  auto backend = openBoard(bus, options);
  REQUIRE(waitFor([&] { return backend->telemetry().haveStatus && bus->validFrames() > 5; }));  // in flight
  bus->delayCallbacks(1e9, kSetPointEndpoint);                                                  // never
  backend->close();
  CHECK(backend->telemetry().transfersLeaked);
  CHECK(bus->closeWaits() == 0);  // given up once, by the driver: the port did not wait again
  CHECK(bus->closesInFlight() > 0);
  CHECK(bus->isOpen());  // leaked with its handle, never freed
  std::string error;
  CHECK_FALSE(backend->open(error));
  CHECK(error == "a USB transfer never completed; restart the server to use the board again");
  CHECK(bus->interfaceClaims() == 1);  // not opened again
}

TEST_CASE("board transfers: after an unplug with a callback that never comes back, the status says restart",
          "[board]") {
  auto bus = EmulatedUsb::create();
  BoardOptions options;
  options.callbackWaitS = 0.05;
  options.reopenPeriodS = 0.02;
  auto backend = openBoard(bus, options);
  REQUIRE(waitFor([&] { return backend->telemetry().haveStatus && bus->validFrames() > 5; }));
  bus->delayCallbacks(1e9, kSetPointEndpoint);
  bus->unplug();
  REQUIRE(waitFor([&] { return backend->telemetry().transfersLeaked; }));
  bus->replug();
  const uint64_t frames = bus->validFrames();
  std::this_thread::sleep_for(100ms);  // five reopen periods
  const BoardTelemetry t = backend->telemetry();
  CHECK_FALSE(t.connected);
  CHECK(t.reopens == 0);
  CHECK(t.lastError.find("restart the server") != std::string::npos);
  CHECK(bus->interfaceClaims() == 1);
  CHECK(bus->validFrames() == frames);
  backend->close();
  CHECK(bus->closeWaits() == 0);
}

TEST_CASE("board reopen: a board without a serial is taken again and the status says it may be another", "[board]") {
  auto bus = EmulatedUsb::create("");
  BoardOptions options;
  options.reopenPeriodS = 0.02;
  auto backend = openBoard(bus, options);
  CHECK(backend->telemetry().lastError.empty());
  bus->unplug();
  REQUIRE(waitFor([&] { return !backend->telemetry().connected; }));
  bus->replug();
  REQUIRE(waitFor([&] { return backend->telemetry().connected; }));
  const BoardTelemetry t = backend->telemetry();
  CHECK(t.lastError.find("without a USB serial") != std::string::npos);
  CHECK(t.lastError.find("may be another board") != std::string::npos);
  CHECK_FALSE(t.armed);
  backend->close();
}
