// What the board driver's tests share: a bounded wait (../WaitFor.hpp), a driver opened on an
// emulated bus, the device's part in arming when the driver runs without one, and a witness of the
// machine's stalls.
#pragma once

#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "../WaitFor.hpp"
#include "board/EmulatedUsb.hpp"
#include "board/UsbBoardBackend.hpp"

namespace kf::test {

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

// A witness of the machine's stalls for [wallclock] tests: a normal-priority thread that asks to
// wake every millisecond and adds up how late it woke, from construction to stop(). A chain of
// threads that must act within a bound on a quiet machine can be held up by no more than the time
// the machine ran no normal thread, so that bound plus stop()'s sum holds on a busy machine too
// (CPU hogs, a second test run) while a fault in the chain still shows beyond it.
class StallWitness {
 public:
  StallWitness() : thread_([this] { run(); }) {}
  ~StallWitness() { stop(); }
  StallWitness(const StallWitness&) = delete;
  StallWitness& operator=(const StallWitness&) = delete;

  // Stops the witness; the seconds it woke late in all, summed.
  double stop() {
    if (thread_.joinable()) {
      stopping_.store(true);
      thread_.join();
    }
    return lateS_;
  }

 private:
  void run() {
    using Clock = std::chrono::steady_clock;
    while (!stopping_.load()) {
      const auto due = Clock::now() + std::chrono::milliseconds(1);
      std::this_thread::sleep_until(due);
      lateS_ += std::chrono::duration<double>(Clock::now() - due).count();
    }
  }

  std::atomic<bool> stopping_{false};
  double lateS_ = 0.0;  // written by the witness's thread, read after its join
  std::thread thread_;  // last: started once the members it uses exist
};

}  // namespace kf::test
