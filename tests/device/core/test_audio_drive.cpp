// The audio drive's chain (AudioDrive, DriveCircuit): force -> safety path per sample -> magnet
// table -> current -> volts -> sample value, and the kf-drive file's checks.
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/force/AudioDrive.hpp"

using namespace kf;

namespace {

// A magnet measured at four currents (fractions of 2 A): exact at its points.
CalibrationTable magnetTable() {
  CalibrationTable table;
  std::string error;
  REQUIRE(CalibrationTable::fromPoints({{0.0, 0.14}, {0.25, 0.41}, {0.5, 0.72}, {1.0, 1.4}}, table, error));
  return table;
}

// 2 A full scale, 0.5 A/V (4 V at full scale) on a 10 V channel, safe up to 2 A.
DriveCircuit circuit(double sign = 1.0, double maxSafeCurrentA = 2.0) {
  DriveCircuit c;
  c.fullScaleCurrentA = 2.0;
  c.transconductanceAPerV = 0.5;
  c.outputFullScaleV = 10.0;
  c.outputSign = sign;
  c.maxSafeCurrentA = maxSafeCurrentA;
  c.magnet = magnetTable();
  return c;
}

constexpr double kFullScaleSample = 2.0 / 0.5 / 10.0;  // drive 1: 4 V of 10 V

// Runs `forces` through a fresh drive, returns the samples.
std::vector<float> drive(const std::vector<float>& forces, const DriveCircuit& c = circuit(), double rateHz = 48000,
                         DeviceSpec spec = {}) {
  AudioDrive audio(spec, c, rateHz);
  std::vector<float> out(forces.size());
  audio.process(forces.data(), static_cast<int>(forces.size()), out.data());
  return out;
}

// Written whole under a name of its own, then renamed into place: ctest runs test cases side by
// side, two of them write the same magnet table, and one read it while the other had it cut to 0
// bytes (a fresh clone's sanitized run). A reader now sees the old text or the new, never a cut one.
std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = std::string(KF_TEST_OUTPUT_DIR) + "/" + name;
  const std::string temporary =
      path + ".tmp" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
  std::ofstream(temporary) << text;
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {  // Windows renames onto no existing file
    std::remove(path.c_str());
    std::rename(temporary.c_str(), path.c_str());
  }
  return path;
}

const char* kGoodDrive =
    "kf-drive 1\n"
    "magnetTable drive-magnet.txt\n"
    "fullScaleCurrentA 2\ntransconductanceAPerV 0.5\noutputFullScaleV 10\noutputSign -1\n"
    "maxSafeCurrentA 1.5\ncurrentSourceLatencyS 0.00002\nmagnetLagS 0.0004\n";

}  // namespace

TEST_CASE("the minimum force drives zero, exactly", "[audio-drive]") {
  for (float sample : drive(std::vector<float>(64, 0.14f))) CHECK(sample == 0.0f);
  for (float sample : drive(std::vector<float>(64, 0.0f))) CHECK(sample == 0.0f);  // below: clamped
}

TEST_CASE("full force drives full scale once slewed, and no more", "[audio-drive]") {
  const std::vector<float> out = drive(std::vector<float>(200, 5.0f));  // above the range
  CHECK(out.back() == static_cast<float>(kFullScaleSample));
  for (float sample : out) CHECK(sample <= static_cast<float>(kFullScaleSample));
}

TEST_CASE("NaN and Inf are the minimum: zero from rest, slewed down from a force", "[audio-drive]") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (float bad : {nan, inf, -inf}) {
    for (float sample : drive(std::vector<float>(16, bad))) CHECK(sample == 0.0f);
    std::vector<float> forces(200, 1.4f);
    forces.resize(400, bad);
    const std::vector<float> out = drive(forces);
    CHECK(out[199] == static_cast<float>(kFullScaleSample));
    CHECK(out[200] < out[199]);
    CHECK(out[200] > 0.0f);  // slewed, not dropped: the board's rule
    CHECK(out.back() == 0.0f);
  }
}

TEST_CASE("a step faster than the slew limit is slewed per sample at every sample rate", "[audio-drive]") {
  const DeviceSpec spec;  // 2000 N/s
  for (double rateHz : {44100.0, 48000.0, 88200.0, 96000.0, 192000.0}) {
    AudioDrive audio(spec, circuit(), rateHz);
    const int n = static_cast<int>(rateHz * 0.002);  // 2 ms: the 1.26 N step takes 0.63 ms
    std::vector<float> forces(n, 1.4f);
    std::vector<float> out(n);
    audio.process(forces.data(), n, out.data());
    // Samples to the top: the step over the per-sample limit, rounded up.
    const double stepN = spec.maxForceSlewNPerS / rateHz;
    const int expected = static_cast<int>(std::ceil((1.4 - 0.14) / stepN - 1e-9));
    int reached = -1;
    for (int i = 0; i < n && reached < 0; ++i)
      if (out[i] == static_cast<float>(kFullScaleSample)) reached = i + 1;
    INFO("rate " << rateHz);
    CHECK(reached == expected);
    // The first sample moved by exactly one step: force 0.14 + step through the table's first segment.
    const double firstDrive = stepN / (0.41 - 0.14) * 0.25;
    CHECK(out[0] == Approx(firstDrive * kFullScaleSample).epsilon(1e-5));
  }
}

TEST_CASE("the magnet table is exact at its points, linear between, clamped at its edges", "[audio-drive]") {
  DeviceSpec spec;
  spec.maxForceSlewNPerS = 1e9;  // no slew: each sample stands alone
  const std::vector<float> out = drive({0.41f, 0.72f, 1.4f, 0.565f, 0.14f, 0.13f, 1.5f}, circuit(), 48000, spec);
  CHECK(out[0] == Approx(0.25 * kFullScaleSample).epsilon(1e-6));
  CHECK(out[1] == Approx(0.5 * kFullScaleSample).epsilon(1e-6));
  CHECK(out[2] == static_cast<float>(kFullScaleSample));
  CHECK(out[3] == Approx(0.375 * kFullScaleSample).epsilon(1e-5));  // halfway from 0.41 to 0.72 N
  CHECK(out[4] == 0.0f);
  CHECK(out[5] == 0.0f);
  CHECK(out[6] == static_cast<float>(kFullScaleSample));
}

TEST_CASE("the output's sign is the channel's", "[audio-drive]") {
  const std::vector<float> out = drive(std::vector<float>(200, 1.4f), circuit(-1.0));
  CHECK(out.back() == static_cast<float>(-kFullScaleSample));
  for (float sample : out) CHECK(sample <= 0.0f);
}

TEST_CASE("the drive never exceeds the circuit's safe current, nor the device's drive limit", "[audio-drive]") {
  const std::vector<float> safe = drive(std::vector<float>(400, 1.4f), circuit(1.0, 1.0));  // safe to 1 A of 2
  for (float sample : safe) CHECK(sample <= static_cast<float>(0.5 * kFullScaleSample));
  CHECK(safe.back() == static_cast<float>(0.5 * kFullScaleSample));
  DeviceSpec spec;
  spec.maxDriveLevel = 0.25;
  const std::vector<float> limited = drive(std::vector<float>(400, 1.4f), circuit(), 48000, spec);
  CHECK(limited.back() == static_cast<float>(0.25 * kFullScaleSample));
}

TEST_CASE("heat derates the drive as on the board", "[audio-drive]") {
  DeviceSpec spec;
  spec.heatTimeConstantS = 0.001;  // hot within a few ms at full drive
  spec.heatRatedDuty = 0.25;       // derated towards drive sqrt(0.25) = 0.5
  const std::vector<float> out = drive(std::vector<float>(4800, 1.4f), circuit(), 48000, spec);
  CHECK(out.back() < static_cast<float>(0.6 * kFullScaleSample));
  CHECK(out.back() >= static_cast<float>(0.5 * kFullScaleSample) - 1e-6f);
}

TEST_CASE("a good kf-drive file loads with its magnet table", "[audio-drive]") {
  writeFile("drive-magnet.txt", magnetTable().toText());
  const std::string path = writeFile("drive-good.txt", kGoodDrive);
  DriveCircuit c;
  std::string error;
  REQUIRE(DriveCircuit::load(path, c, error));
  CHECK(c.outputSign == -1.0);
  CHECK(c.maxSafeCurrentA == 1.5);
  CHECK(c.circuitLatencyS() == Approx(0.00042));
  CHECK(c.magnet.points().size() == 4);
}

TEST_CASE("inconsistent or broken kf-drive files are refused with the reason", "[audio-drive]") {
  writeFile("drive-magnet.txt", magnetTable().toText());
  writeFile("drive-magnet-bad.txt", "kf-calibration 1\n0 0.5\n0.5 0.3\n");
  writeFile("drive-magnet-offset.txt", "kf-calibration 1\n0.5 0.14\n1 1.4\n");
  const std::string good = kGoodDrive;
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "is empty"},
      {replaced("kf-drive 1", "kf-calibration 1"), "expected the header \"kf-drive 1\""},
      {replaced("kf-drive 1", "kf-drive 2"), "version 2"},
      {replaced("outputSign -1", "outputSign 0.5"), "outputSign 0.5 is not 1 or -1"},
      {replaced("outputFullScaleV 10", "outputFullScaleV nan"), "expected \"outputFullScaleV <number>\""},
      {replaced("outputFullScaleV 10", "outputFullScaleV 0"), "outputFullScaleV 0 is not in (0, 100]"},
      {replaced("maxSafeCurrentA 1.5", "maxSafeCurrentA -1"), "maxSafeCurrentA -1 is not in"},
      {replaced("magnetLagS 0.0004\n", ""), "magnetLagS is missing"},
      // The coil's L/R was once declared as if it were a delay: refused, saying what to declare.
      {replaced("magnetLagS", "coilTimeConstantS"), "coilTimeConstantS is no longer a field: declare magnetLagS"},
      {replaced("outputSign -1", "outputSign -1\noutputSign 1"), "outputSign is given twice"},
      {replaced("outputSign -1", "outputGain 2"), "unknown field \"outputGain\""},
      {replaced("magnetTable drive-magnet.txt\n", ""), "magnetTable is missing"},
      {replaced("drive-magnet.txt", "drive-magnet-none.txt"), "drive-magnet-none.txt: cannot open"},
      {replaced("drive-magnet.txt", "drive-magnet-bad.txt"), "not monotone"},
      // 2 V full scale x 0.5 A/V = 1 A, less than the 1.5 A the drive may ask for.
      {replaced("outputFullScaleV 10", "outputFullScaleV 2"), "gives at most 1 A, less than the 1.5 A"},
      // The magnet's least force needs 1 A (0.5 of 2 A): a 0.8 A circuit cannot drive it off.
      {replaced("drive-magnet.txt", "drive-magnet-offset.txt\n") + "", "could not even be driven off"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    std::string text = cases[i].first;
    if (i == cases.size() - 1) text.replace(text.find("maxSafeCurrentA 1.5"), 19, "maxSafeCurrentA 0.8");
    const std::string path = writeFile("drive-bad.txt", text);
    DriveCircuit c;
    std::string error;
    INFO("case " << i << ": " << text);
    CHECK_FALSE(DriveCircuit::load(path, c, error));
    CHECK_THAT(error, Catch::Contains(cases[i].second));
  }
}
