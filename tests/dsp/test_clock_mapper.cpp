// DeviceClockMapper: lockstep exactness, the lower envelope under block/queue jitter, drift
// of +-200 ppm, gaps, restarts, and mapped time never going backward.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "DeviceClockMapper.hpp"

using kf::DeviceClockMapper;

namespace {

constexpr double kReportS = 0.008;          // 125 Hz
constexpr double kBlockS = 64.0 / 48000.0;  // arrivals are seen at audio block starts
constexpr double kLatencyS = 0.003;         // true latency: device -> earliest arrival

// A device clock against the audio clock: audio = device * (1 + ppm) + offset.
struct Link {
  double ppm = 0.0;
  double offsetS = 12.345;
  std::mt19937 rng{1};
  std::uniform_real_distribution<double> queueS{0.0, 0.0004};

  double trueAudioS(double deviceS) const { return deviceS * (1.0 + ppm * 1e-6) + offsetS; }
  // Earliest possible arrival plus queue delay, seen at the next block start.
  double arrivalS(double deviceS) {
    const double t = trueAudioS(deviceS) + kLatencyS + queueS(rng);
    return std::ceil(t / kBlockS) * kBlockS;
  }
};

}  // namespace

TEST_CASE("DeviceClockMapper: lockstep maps every time exactly", "[clock]") {
  DeviceClockMapper mapper;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> step(0.0005, 0.02);
  double t = 0.0;
  for (int k = 0; k < 20000; ++k) {
    t += step(rng);
    REQUIRE(mapper.map(t, t) == t);
    REQUIRE(mapper.offsetS() == 0.0);
  }
  CHECK(mapper.resetCount() == 0);
  CHECK(mapper.mapOnly(t + 1.0) == t + 1.0);
}

namespace {

// Error of the mapped times against the true floor (device -> earliest arrival), after a
// warm-up, and how much it wanders.
struct Stats {
  double lowestS = 1e9, highestS = -1e9;  // error range
  double largestStepS = 0.0;              // between successive reports
  double largestSpreadS = 0.0;            // within any 1 s (125 reports)
  bool increasing = true;
};

Stats run(double ppm, double seconds, double warmUpS = 10.0) {
  Link link;
  link.ppm = ppm;
  DeviceClockMapper mapper;
  Stats st;
  double lastMappedS = -1e9, lastErrorS = 0.0;
  std::vector<double> window;
  const int reports = static_cast<int>(seconds / kReportS);
  for (int k = 0; k < reports; ++k) {
    const double deviceS = 5000.0 + k * kReportS;
    const double mappedS = mapper.map(deviceS, link.arrivalS(deviceS));
    if (!(mappedS > lastMappedS)) st.increasing = false;
    lastMappedS = mappedS;
    const double errorS = mappedS - (link.trueAudioS(deviceS) + kLatencyS);
    if (k * kReportS >= warmUpS) {
      st.lowestS = std::min(st.lowestS, errorS);
      st.highestS = std::max(st.highestS, errorS);
      st.largestStepS = std::max(st.largestStepS, std::fabs(errorS - lastErrorS));
      window.push_back(errorS);
      if (window.size() == 125) {
        const auto mm = std::minmax_element(window.begin(), window.end());
        st.largestSpreadS = std::max(st.largestSpreadS, *mm.second - *mm.first);
        window.erase(window.begin(), window.begin() + 25);
      }
    }
    lastErrorS = errorS;
  }
  return st;
}

}  // namespace

TEST_CASE("DeviceClockMapper: follows the floor under jitter and +-200 ppm drift", "[clock]") {
  // Arrivals are late by 0..1.33 ms (block) + 0..0.4 ms (queue). 125 Hz against 1.33 ms
  // blocks repeats the same phase, so the floor itself is seen only as drift walks the phase.
  for (double ppm : {-200.0, -100.0, -20.0, 0.0, 5.0, 20.0, 100.0, 200.0}) {
    const Stats st = run(ppm, 600.0);
    INFO("ppm " << ppm << ": error " << st.lowestS * 1e3 << " .. " << st.highestS * 1e3 << " ms, largest step "
                << st.largestStepS * 1e3 << " ms, largest 1 s spread " << st.largestSpreadS * 1e3 << " ms");
    CHECK(st.increasing);
    // Never much before the floor, never later than the jitter (1.73 ms) allows.
    CHECK(st.lowestS > -1e-4);
    CHECK(st.highestS < 1.6e-3);
    // Smooth: report times move by microseconds from one report to the next, not by blocks.
    CHECK(st.largestStepS < 2e-5);
    CHECK(st.largestSpreadS < 0.8e-3);
  }
}

TEST_CASE("DeviceClockMapper: a 100 ms gap changes nothing", "[clock]") {
  Link link;
  link.ppm = 150.0;
  DeviceClockMapper mapper;
  double deviceS = 1.0, lastMappedS = -1e9, lastErrorS = 0.0;
  for (int k = 0; k < 4000; ++k) {
    deviceS += (k == 2000) ? 0.1 : kReportS;
    const double mappedS = mapper.map(deviceS, link.arrivalS(deviceS));
    REQUIRE(mappedS > lastMappedS);
    lastMappedS = mappedS;
    const double errorS = mappedS - (link.trueAudioS(deviceS) + kLatencyS);
    if (k >= 1000) {
      CHECK(errorS > -1e-4);
      CHECK(errorS < 1.6e-3);
      CHECK(std::fabs(errorS - lastErrorS) < 5e-5);  // across the gap too
    }
    lastErrorS = errorS;
  }
  CHECK(mapper.resetCount() == 0);
}

TEST_CASE("DeviceClockMapper: a restarted device (time going back) resets it", "[clock]") {
  Link link;
  DeviceClockMapper mapper;
  for (int k = 0; k < 500; ++k) mapper.map(50.0 + k * kReportS, link.arrivalS(50.0 + k * kReportS));
  // The device restarts: its clock begins again near 0 while audio time goes on.
  link.offsetS += 54.0;
  double lastMappedS = -1e9;
  for (int k = 0; k < 500; ++k) {
    const double deviceS = 0.01 + k * kReportS;
    const double mappedS = mapper.map(deviceS, link.arrivalS(deviceS));
    if (k > 0) REQUIRE(mappedS > lastMappedS);
    lastMappedS = mappedS;
    const double errorS = mappedS - (link.trueAudioS(deviceS) + kLatencyS);
    CHECK(errorS > -1e-4);
    CHECK(errorS < 1.8e-3);
  }
  CHECK(mapper.resetCount() == 1);
}

TEST_CASE("DeviceClockMapper: a device clock jumping forward resets it", "[clock]") {
  Link link;
  DeviceClockMapper mapper;
  for (int k = 0; k < 500; ++k) mapper.map(10.0 + k * kReportS, link.arrivalS(10.0 + k * kReportS));
  link.offsetS -= 30.0;  // device time 30 s ahead of where it was: arrival - device drops 30 s
  for (int k = 0; k < 500; ++k) {
    const double deviceS = 44.0 + k * kReportS;
    const double errorS = mapper.map(deviceS, link.arrivalS(deviceS)) - (link.trueAudioS(deviceS) + kLatencyS);
    CHECK(errorS > -1e-4);
    CHECK(errorS < 1.8e-3);
  }
  CHECK(mapper.resetCount() == 1);
}

TEST_CASE("DeviceClockMapper: a late start and bursts never map backward", "[clock]") {
  DeviceClockMapper mapper;
  double lastMappedS = -1e9;
  // The first 40 reports queued up behind a 50 ms stall and arrive together.
  for (int k = 0; k < 40; ++k) {
    const double deviceS = k * kReportS;
    const double mappedS = mapper.map(deviceS, 0.32 + 0.003);
    REQUIRE(mappedS > lastMappedS);
    lastMappedS = mappedS;
  }
  // Then on time (3 ms latency): the estimate comes down, mapped time still advancing.
  for (int k = 40; k < 400; ++k) {
    const double deviceS = k * kReportS;
    const double mappedS = mapper.map(deviceS, deviceS + 0.003);
    REQUIRE(mappedS - lastMappedS >= 0.5 * kReportS - 1e-12);
    lastMappedS = mappedS;
    if (k >= 100) CHECK(mappedS == Approx(deviceS + 0.003).margin(1e-9));
  }
  CHECK(mapper.resetCount() == 0);
}

TEST_CASE("DeviceClockMapper: extra latency is added to every mapped time", "[clock]") {
  DeviceClockMapper::Config config;
  config.extraLatencyS = 0.002;
  DeviceClockMapper mapper(config);
  CHECK(mapper.map(1.0, 1.0) == Approx(1.002));
  CHECK(mapper.map(1.008, 1.008) == Approx(1.010));
  CHECK(mapper.offsetS() == 0.0);
}
