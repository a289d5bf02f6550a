// The friction board through the real kernel and the real libusb: the board's firmware runs as
// a USB gadget on dummy_hcd through FunctionFS (kf_board_gadget, guest/GadgetBoard.hpp) and our
// driver (UsbBoardBackend with the real LibusbPort) talks to it over usbfs.
#include <catch2/catch.hpp>

#include <cstdio>
#include <memory>
#include <string>

#include "board/UsbBoardBackend.hpp"
#include "guest/GadgetBoard.hpp"
#include "guest/GuestSystem.hpp"

using namespace kf;
using kf::guest::GadgetBoard;
using kf::guest::GadgetReport;

namespace {

std::unique_ptr<UsbBoardBackend> openBoard(const std::string& serial, std::string& error, BoardOptions options = {}) {
  options.ids.serial = serial;
  auto backend = std::make_unique<UsbBoardBackend>(usb::makeLibusbPort(), options);
  if (!backend->open(error)) return nullptr;
  return backend;
}

}  // namespace

TEST_CASE("board gadget: the driver opens it through libusb by its identity and serial", "[gadget]") {
  GadgetBoard gadget;
  std::string error;
  auto board = openBoard(GadgetBoard::kSerial, error);
  INFO(error);
  REQUIRE(board != nullptr);
  const BoardTelemetry t = board->telemetry();
  CHECK(t.serial == GadgetBoard::kSerial);
  CHECK(t.version.protocolMajor == board::kProtocolMajor);
  CHECK(t.boardResets == 1);
  REQUIRE(kf::guest::waitUntil([&] { return board->telemetry().haveStatus; }, 10.0));
  board->close();
  const GadgetReport report = gadget.report();
  std::printf("gadget: %zu frames, %zu controls, %zu status frames taken, events:", report.frames.size(),
              report.controls.size(), report.statuses.size());
  for (const auto& event : report.events) std::printf(" %s", event.name.c_str());
  std::printf("\n");
  CHECK(report.controlsOf(0x01).size() == 1);  // GET_VERSION
  CHECK(report.controlsOf(0x04).size() == 1);  // CLEAR_ERRORS
  CHECK(report.controlsOf(0x03).size() == 1);  // DISARM at close
}
