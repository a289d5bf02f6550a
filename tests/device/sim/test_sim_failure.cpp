// The simulated device's failure on request (kfSimFail): its next poll throws as a driver that
// lost its device would, and a realtime device's thread then stops with the magnet off.
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <thread>

#include "core/Device.hpp"
#include "sim/SimDevice.hpp"

using namespace kf;

TEST_CASE("a simulated device asked to fail throws at its next poll, once", "[sim]") {
  SimDevice sim(DeviceSpec{}, SimParams{}, HandScript::constantForce(0.5));
  MouseReport reports[16];
  sim.pollReports(0.1, reports, 16);
  sim.failNextPoll();
  CHECK_THROWS_AS(sim.pollReports(0.2, reports, 16), std::runtime_error);
  CHECK_NOTHROW(sim.pollReports(0.3, reports, 16));
}

TEST_CASE("a realtime simulated device asked to fail stops its thread with the magnet off", "[sim][wallclock]") {
  const DeviceSpec spec;
  auto sim = std::make_shared<SimDevice>(spec, SimParams{}, HandScript::constantForce(0.5));
  Device device(spec, sim, sim, false);
  device.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  CHECK_FALSE(device.threadFailed());
  sim->failNextPoll();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!device.threadFailed() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  CHECK(device.threadFailed());
  CHECK(device.telemetry().lastCommandedForceN == Approx(spec.minForceN));
  device.close();
}
