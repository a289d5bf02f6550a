// What the board driver's tests share: a bounded wait, a driver opened on an emulated bus, and
// the device's part in arming when the driver runs without one.
#pragma once

#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "board/EmulatedUsb.hpp"
#include "board/UsbBoardBackend.hpp"

namespace kf::test {

// Waits until `done` holds; false after `limit` (which only a failing test reaches).
template <class Done>
bool waitFor(Done done, std::chrono::milliseconds limit = std::chrono::milliseconds(3000)) {
  const auto start = std::chrono::steady_clock::now();
  while (!done()) {
    if (std::chrono::steady_clock::now() - start > limit) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

inline std::shared_ptr<UsbBoardBackend> openBoard(const std::shared_ptr<board::EmulatedUsb>& bus,
                                                  BoardOptions options = {}) {
  auto backend = std::make_shared<UsbBoardBackend>(bus->makePort(), options);
  std::string error;
  INFO(error);
  REQUIRE(backend->open(error));
  return backend;
}

// Arms a board driven without a Device, playing the device's part: ARM restarts the force from
// off, and the device acknowledges that (takeRestartFromOff) before its next frame.
inline bool armAlone(UsbBoardBackend& backend, std::string& error) {
  if (!backend.arm(error)) return false;
  backend.takeRestartFromOff();
  return true;
}

}  // namespace kf::test
