// Issue 13, items 1 and 2: every setting and file field bounded in one place; parsers that
// cannot be driven into unbounded work; special files refused before reading; one message
// per kind of bad file; a recording cut mid-line loads up to that line with a warning.
#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "DeviceFactory.hpp"
#include "core/files/SessionFile.hpp"
#include "core/spec/DeviceSpec.hpp"
#include "core/spec/SettingBounds.hpp"
#include "hid/HidMouseDecoder.hpp"
#include "hid/HidReportDescriptor.hpp"
#include "recordings/HidRecorderFile.hpp"
#include "recordings/ReplayBackend.hpp"
#include "sim/HandScript.hpp"
#include "sim/SimParams.hpp"

using namespace kf;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

std::string outputPath(const std::string& name) { return std::string(KF_TEST_OUTPUT_DIR) + "/bounds-" + name; }

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = outputPath(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string sessionHeader(const std::string& extra = "") {
  return "kf-session 1 countMm=0.021 updateRateHz=125 maxCountsPerReport=127 minForceN=0.14 maxForceN=1.4" + extra +
         "\n";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("the bounds table: field, value and range in every refusal", "[bounds]") {
  DeviceSpec spec;
  std::string error;
  CHECK_FALSE(spec.applyOverride("forceFramePeriodS", 1e-30, &error));
  CHECK(error == "forceFramePeriodS = 1e-30 is out of range 0.0001..0.1 s");
  CHECK_FALSE(spec.applyOverride("updateRateHz", 1e30, &error));
  CHECK(contains(error, "updateRateHz = 1e+30 is out of range 1..8000 Hz"));
  CHECK_FALSE(spec.applyOverride("countMm", 1e300, &error));
  CHECK(contains(error, "countMm = 1e+300"));
  CHECK_FALSE(spec.applyOverride("maxCountsPerReport", 1.5, &error));
  CHECK(contains(error, "whole numbers"));
  CHECK_FALSE(spec.applyOverride("noSuchField", 1.0, &error));
  CHECK(contains(error, "unknown"));
  CHECK(spec.isValid());  // nothing changed

  SimParams sim;
  for (double stepS : {1e-12, 1e-30, 0.0, -1e-4, 1.0, kNaN, kInf}) {
    CHECK_FALSE(sim.applyOverride("stepS", stepS, &error));
    CHECK(contains(error, "stepS = "));
  }
  CHECK(sim.stepS == 1e-4);
  CHECK(sim.applyOverride("stepS", 1e-5));

  // Every numeric field: NaN, infinities and absurd magnitudes refused; defaults allowed.
  const char* specKeys[] = {"countMm",           "updateRateHz",  "maxCountsPerReport", "minForceN",
                            "maxForceN",         "audioLatencyS", "tactileLatencyS",    "forceFramePeriodS",
                            "maxForceSlewNPerS", "watchdogS",     "magnetLagS"};
  for (const char* key : specKeys) {
    INFO(key);
    REQUIRE(findSettingBounds(key) != nullptr);
    DeviceSpec probe;
    for (double bad : {kNaN, kInf, -kInf, 1e300, -1e300}) CHECK_FALSE(probe.applyOverride(key, bad));
  }
  CHECK(DeviceSpec{}.isValid());
  CHECK(SimParams{}.isValid());

  // The whole spec is checked too (a C++ caller may set fields directly).
  spec.forceFramePeriodS = 1e-30;
  CHECK_FALSE(spec.isValid(&error));
  CHECK(contains(error, "forceFramePeriodS"));
  spec = DeviceSpec{};
  spec.watchdogS = 0.002;
  spec.forceFramePeriodS = 0.002;
  CHECK_FALSE(spec.isValid(&error));
  CHECK(contains(error, "watchdogS"));
}

TEST_CASE("hand scripts are bounded, so the simulated puck stays finite", "[bounds]") {
  CHECK_FALSE(HandScript::constantForce(1e300).isValid());
  CHECK(HandScript::constantForce(1.0).isValid());
  CHECK_FALSE(HandScript::speeds({{1e300, 1.0}}).isValid());
  CHECK_FALSE(HandScript::speeds({{100.0, 1e300}}).isValid());
  CHECK_FALSE(HandScript::path({{0.0, 0.0}, {1.0, 1e300}}).isValid());
  std::string error;
  CHECK(openSimDevice(DeviceSpec{}, SimParams{}, HandScript::constantForce(1e300), true, &error) == nullptr);
  CHECK(contains(error, "hand script"));
  SimParams sim;
  sim.stepS = 1e-30;  // set directly, not through applyOverride
  CHECK(openSimDevice(DeviceSpec{}, sim, HandScript::none(), false, &error) == nullptr);
  CHECK(contains(error, "stepS"));
}

TEST_CASE("session-file headers obey the same bounds", "[bounds][session]") {
  DeviceSpec spec;
  SessionData session;
  std::string error;
  for (const char* field : {" forceFramePeriodS=1e-300", " updateRateHz=1e30", " countMm=1e300", " watchdogS=nan"}) {
    INFO(field);
    const std::string path = writeFile("header.txt", sessionHeader(field) + "R 0.008 0.008 1 0 0 0\n");
    CHECK_FALSE(readSessionFile(path, spec, session, error));
    CHECK(contains(error, ":1: header: "));
    CHECK(contains(error, std::string(field).substr(1, std::string(field).find('=') - 1)));
    CHECK(openReplayDevice(path, spec, true, error) == nullptr);
  }
  // Unknown keys (a newer writer) are still skipped; non-finite report times are malformed.
  const std::string newer = writeFile("newer.txt", sessionHeader(" futureFieldHz=1e300") + "R 0.008 0.008 1 0 0 0\n");
  CHECK(readSessionFile(newer, spec, session, error));
  const std::string nanTime = writeFile("nan-time.txt", sessionHeader() + "R nan 0.008 1 0 0 0\n");
  CHECK_FALSE(readSessionFile(nanTime, spec, session, error));
  CHECK(contains(error, ":2: malformed 'R'"));
}

TEST_CASE("a usage range ending at 0xFFFFFFFF ends", "[bounds][hid]") {
  // Usage Minimum 0xFFFF0000, Usage Maximum 0xFFFFFFFF (4-byte items), one 8-bit Input. The
  // loop used to compare against the maximum and wrap around forever.
  const std::vector<uint8_t> bytes = {0x1B, 0x00, 0x00, 0xFF, 0xFF, 0x2B, 0xFF, 0xFF,
                                      0xFF, 0xFF, 0x75, 0x08, 0x95, 0x01, 0x81, 0x00};
  HidReportDescriptor descriptor;
  std::string error;
  REQUIRE(parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error));
  REQUIRE(descriptor.fields.size() == 1);
  CHECK(descriptor.fields[0].usages.size() == 65536);
  CHECK(descriptor.fields[0].usages.back() == 0xFFFFFFFFu);

  // An item with a range of more than one page is skipped (its report with it), and so is one
  // that takes the usages in all beyond 2^18: nothing of them is kept.
  const std::vector<uint8_t> wide = {0x1B, 0x00, 0x00, 0x00, 0x00, 0x2B, 0xFF, 0xFF,
                                     0xFF, 0xFF, 0x75, 0x08, 0x95, 0x01, 0x81, 0x00};
  REQUIRE(parseHidReportDescriptor(wide.data(), wide.size(), descriptor, error));
  CHECK(descriptor.fields.empty());
  CHECK(descriptor.skippedItems == 1);
  std::vector<uint8_t> many;
  for (int i = 0; i < 8; ++i)
    many.insert(many.end(), {0x19, 0x00, 0x2A, 0xFF, 0xFF, 0x75, 0x01, 0x95, 0x01, 0x81, 0x00});
  REQUIRE(parseHidReportDescriptor(many.data(), many.size(), descriptor, error));
  CHECK(descriptor.fields.empty());
  REQUIRE_FALSE(descriptor.skipNotes.empty());
  CHECK(contains(descriptor.skipNotes.back(), "usages in all"));
}

TEST_CASE("an array of 30720 button elements is decoded without copying its usages", "[bounds][hid]") {
  // Button page, usages 0..0xFFFF, 1-bit array elements x 32768, then a relative X: the decoder
  // used to copy the 65536 usages once per element (8 GiB).
  const std::vector<uint8_t> bytes = {0x05, 0x09, 0x19, 0x00, 0x2A, 0xFF, 0xFF, 0x15, 0x00, 0x26,
                                      0xFF, 0x00, 0x75, 0x01, 0x96, 0x00, 0x78, 0x81, 0x00,  // 30720 elements
                                      0x05, 0x01, 0x09, 0x30, 0x15, 0x81, 0x25, 0x7F, 0x75, 0x08,
                                      0x95, 0x01, 0x81, 0x06};
  HidReportDescriptor descriptor;
  std::string error;
  REQUIRE(parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error));
  HidMouseDecoder decoder;
  const auto start = std::chrono::steady_clock::now();
  REQUIRE(decoder.build(descriptor, error));
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(5));  // was minutes, or bad_alloc
  std::vector<uint8_t> report(30720 / 8 + 1, 0);
  report[0] = 0x02;  // first element selects usage 2 - 0: Button 2
  report.back() = 0x05;
  HidMouseDelta delta;
  REQUIRE(decoder.decode(report.data(), report.size(), delta));
  CHECK(delta.dxCounts == 5);
}

TEST_CASE("special files are refused before reading, each bad file with its own message", "[bounds][files]") {
  DeviceSpec spec;
  std::vector<TimedReport> reports;
  std::string error;
  auto refusal = [&](const std::string& path) {
    const auto start = std::chrono::steady_clock::now();
    CHECK_FALSE(loadReplayReports(path, spec, reports, error));
    CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(2));  // no read of a FIFO or /dev/zero
    return error;
  };
  const std::string fifo = outputPath("fifo");
  ::unlink(fifo.c_str());
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK(contains(refusal(fifo), "not a regular file"));
  CHECK(contains(refusal("/dev/zero"), "not a regular file"));
  CHECK(contains(refusal(KF_TEST_OUTPUT_DIR), "is a directory"));
  CHECK(contains(refusal(outputPath("no-such-file")), "no such file"));
  CHECK(contains(refusal(writeFile("empty.txt", "")), "is empty"));
  CHECK(contains(refusal(writeFile("comments.txt", "# nothing\n\n")), "neither a kf-session nor a hid-recorder"));
  CHECK(contains(refusal(writeFile("malformed.txt", sessionHeader() + "R 1 2 x\n")), ":2: malformed 'R' record"));
  CHECK(contains(refusal(writeFile("long.txt", sessionHeader() + "# " + std::string(5000, 'x') + "\n")),
                 ":2: line longer than 4096"));
  if (::geteuid() != 0) {  // root reads anything
    const std::string locked = writeFile("locked.txt", sessionHeader());
    ::chmod(locked.c_str(), 0);
    CHECK(contains(refusal(locked), "permission denied"));
  }
  ::unlink(fifo.c_str());
}

TEST_CASE("a recording cut mid-line loads up to that line, with a warning", "[bounds][files]") {
  DeviceSpec spec;
  std::vector<TimedReport> reports;
  std::string error, warning;
  const std::string session = writeFile(
      "cut.txt", sessionHeader() + "R 0.008 0.008 1 0 0 0\nF 0.009 0.008 0.4 0.4\nR 0.016 0.016 2 0 0 0\nR 0.02");
  REQUIRE(loadReplayReports(session, spec, reports, error, nullptr, &warning));
  CHECK(reports.size() == 2);
  CHECK(contains(warning, ":5: the last line was cut"));
  // A whole file, or a header cut after its last field, loads without a warning.
  REQUIRE(loadReplayReports(writeFile("whole.txt", sessionHeader() + "R 0.008 0.008 1 0 0 0\n"), spec, reports, error,
                            nullptr, &warning));
  CHECK(warning.empty());

  // hid-recorder: the real recording with its last event cut in half.
  std::string text = readAll(KF_HID_RECORDING);
  size_t fullEvents = 0;
  REQUIRE(loadReplayReports(KF_HID_RECORDING, spec, reports, error, nullptr, &warning));
  fullEvents = reports.size();
  CHECK(warning.empty());
  while (!text.empty() && text.back() == '\n') text.pop_back();
  text.resize(text.size() - 4);
  REQUIRE(loadReplayReports(writeFile("cut.hid", text), spec, reports, error, nullptr, &warning));
  CHECK(reports.size() == fullEvents - 1);
  CHECK(contains(warning, "the last line was cut"));
}
