// The firmware author's rules of device/board/PROTOCOL.md that the board emulator models, on
// explicit times: CLEAR_ERRORS and what persists, the reset reported once, ARM while armed,
// the watchdog idle while disarmed, suspend and bus reset.
#include <catch2/catch.hpp>

#include "board/BoardEmulator.hpp"

using namespace kf;
using namespace kf::board;

namespace {

constexpr uint8_t kOut = 0x41, kIn = 0xC1;

ClearReply clearErrors(BoardEmulator& board, double nowS) {
  uint8_t data[kClearReplySize] = {};
  int moved = 0;
  REQUIRE(board.control(kIn, static_cast<uint8_t>(Request::kClearErrors), 0, data, kClearReplySize, &moved, nowS) ==
          usb::Result::kOk);
  ClearReply reply;
  REQUIRE(decodeClearReply(data, static_cast<size_t>(moved), reply));
  return reply;
}

usb::Result arm(BoardEmulator& board, double nowS) {
  return board.control(kOut, static_cast<uint8_t>(Request::kArm), kArmKey, nullptr, 0, nullptr, nowS);
}

void send(BoardEmulator& board, uint16_t sequence, uint16_t drive, double nowS) {
  uint8_t frame[kSetPointSize];
  encodeSetPoint({sequence, drive}, frame);
  board.receiveSetPoint(frame, kSetPointSize, nowS);
}

}  // namespace

TEST_CASE("board rules: the power-on reset is reported once, until CLEAR_ERRORS", "[board]") {
  BoardEmulator board(0.0);
  CHECK((board.status(0.001).errors & kErrUsbReset) != 0);  // enumerated: reported...
  CHECK((board.status(0.002).errors & kErrUsbReset) != 0);  // ...in every frame until acknowledged
  const ClearReply reply = clearErrors(board, 0.003);
  CHECK(reply.before == kErrUsbReset);
  CHECK(reply.remaining == 0);
  CHECK(board.status(0.004).errors == 0);  // once: not a bit stuck for ever
  // CLEAR_ERRORS is an IN request now: the OUT form of protocol 1 is refused.
  CHECK(board.control(kOut, static_cast<uint8_t>(Request::kClearErrors), 0, nullptr, 0, nullptr, 0.005) ==
        usb::Result::kPipe);
  board.powerOn(0.01);  // plugged in again
  CHECK((board.status(0.011).errors & kErrUsbReset) != 0);
}

TEST_CASE("board rules: an over-current trip clears without a power cycle, one that persists says so", "[board]") {
  BoardEmulator board(0.0);
  clearErrors(board, 0.0);
  REQUIRE(arm(board, 0.0) == usb::Result::kOk);
  send(board, 1, 30000, 0.001);
  board.overCurrent(0.002, /*persists=*/true);
  CHECK(board.drive() == 0);
  CHECK(board.state() == BoardState::kFault);
  CHECK(arm(board, 0.003) == usb::Result::kPipe);
  ClearReply reply = clearErrors(board, 0.004);
  CHECK((reply.before & kErrOverCurrent) != 0);
  CHECK(reply.remaining == kErrOverCurrent);  // the cause is still there: the board says so
  CHECK(board.state() == BoardState::kFault);
  CHECK(arm(board, 0.005) == usb::Result::kPipe);
  board.setOverCurrent(false);  // the short is fixed
  reply = clearErrors(board, 0.006);
  CHECK(reply.remaining == 0);
  CHECK(board.state() == BoardState::kDisarmed);
  CHECK(arm(board, 0.007) == usb::Result::kOk);
  // A trip that does not persist clears at once.
  board.overCurrent(0.008, /*persists=*/false);
  CHECK(clearErrors(board, 0.009).remaining == 0);
  CHECK(board.state() == BoardState::kDisarmed);
}

TEST_CASE("board rules: ARM while armed changes nothing", "[board]") {
  BoardEmulator board(0.0);
  REQUIRE(arm(board, 0.0) == usb::Result::kOk);
  send(board, 100, 30000, 0.001);
  REQUIRE(arm(board, 0.002) == usb::Result::kOk);  // acknowledged
  CHECK(board.drive() == 30000);                   // the current is not interrupted
  CHECK(board.state() == BoardState::kArmed);
  send(board, 50, 1000, 0.003);  // the sequence is not forgotten: an old frame is still stale
  CHECK(board.drive() == 30000);
  CHECK(board.rejectedFrames() == 1);
  // Nor is the watchdog fed by it: off 20 ms after the last valid set-point (0.001).
  board.advance(0.0215);
  CHECK(board.drive() == 0);
  CHECK(board.offTimeAfter(0.0) == Approx(0.001 + kBoardWatchdogS));
}

TEST_CASE("board rules: the watchdog is idle while disarmed and starts with ARM", "[board]") {
  BoardEmulator board(0.0);
  clearErrors(board, 0.0);
  send(board, 1, 30000, 0.001);  // disarmed: drive 0, and no watchdog to trip later
  board.advance(1.0);
  CHECK(board.errors() == 0);
  REQUIRE(arm(board, 1.0) == usb::Result::kOk);
  board.advance(1.0 + kBoardWatchdogS - 0.001);
  CHECK(board.errors() == 0);
  board.advance(1.0 + kBoardWatchdogS + 0.001);  // armed and no set-point for 20 ms: reported
  CHECK((board.errors() & kErrWatchdog) != 0);
  CHECK(board.state() == BoardState::kArmed);  // still armed: the next set-point drives
  send(board, 2, 500, 1.03);
  CHECK(board.drive() == 500);
  // Disarmed after a set-point: the watchdog stops with it and reports nothing.
  clearErrors(board, 1.031);
  REQUIRE(board.control(kOut, static_cast<uint8_t>(Request::kDisarm), 0, nullptr, 0, nullptr, 1.032) ==
          usb::Result::kOk);
  board.advance(1.2);
  CHECK(board.errors() == 0);
}

TEST_CASE("board rules: suspend and bus reset turn the current off and disarm", "[board]") {
  for (const char* why : {"suspend", "usb reset"}) {
    BoardEmulator board(0.0);
    clearErrors(board, 0.0);
    REQUIRE(arm(board, 0.0) == usb::Result::kOk);
    send(board, 1, 40000, 0.001);
    board.usbReset(0.002, why);
    CHECK(board.drive() == 0);
    CHECK(board.offTimeAfter(0.001) == 0.002);
    CHECK(board.state() == BoardState::kDisarmed);
    CHECK((board.errors() & kErrUsbReset) != 0);
    send(board, 2, 40000, 0.003);  // resumed: set-points alone do not drive
    CHECK(board.drive() == 0);
    CHECK(clearErrors(board, 0.004).before == kErrUsbReset);
  }
}
