// The synthetic recordings of tests/data/hid (125 Hz 8-bit, 1 kHz 12-bit, 8 kHz 16-bit, 250 Hz
// with its buttons apart; see its README) replayed and compared with the trajectory they were made from: the position
// within the sensor's rounding until a report saturates; every report that lost movement flagged
// saturated, none flagged that did not; buttons as pressed; and through the reconstruction, the
// position error and lag per rate.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "SyntheticRecordings.hpp"
#include "hid/HidMouseDecoder.hpp"
#include "hid/HidReportDescriptor.hpp"
#include "recordings/HidRecorderFile.hpp"
#include "recordings/ReplayBackend.hpp"

using namespace kf;
using kf::test::SyntheticMouse;
using kf::test::SyntheticTrajectory;

namespace {
std::string dataPath(const char* file) { return std::string(KF_HID_DATA_DIR) + "/" + file; }

SyntheticTrajectory loadTruth() {
  SyntheticTrajectory truth;
  std::string error;
  INFO(error);
  REQUIRE(truth.load(dataPath("synthetic-trajectory.csv"), error));
  return truth;
}
}  // namespace

TEST_CASE("synthetic recordings' descriptors: the mouse report found beside vendor, feature and consumer reports",
          "[hid][recordings]") {
  // (mouse report ID, input report bytes, reports of other kinds or IDs the descriptor declares)
  const struct {
    uint8_t mouseId;
    size_t bytes, otherFields;
  } expected[] = {{0, 4, 0}, {2, 8, 5}, {1, 8, 3}};
  for (size_t i = 0; i < kf::test::syntheticMice().size(); ++i) {
    const SyntheticMouse& mouse = kf::test::syntheticMice()[i];
    INFO(mouse.file);
    HidRecording recording;
    std::string error;
    REQUIRE(readHidRecorderFile(dataPath(mouse.file), recording, error));
    HidReportDescriptor descriptor;
    REQUIRE(parseHidReportDescriptor(recording.descriptor.data(), recording.descriptor.size(), descriptor, error));
    CHECK(descriptor.skippedItems == 0);
    CHECK(descriptor.inputReportBytes(expected[i].mouseId) == expected[i].bytes);
    size_t other = 0;
    for (const HidField& field : descriptor.fields)
      other += field.reportId != expected[i].mouseId || field.kind != HidField::Kind::kInput;
    CHECK(other == expected[i].otherFields);
    HidMouseDecoder decoder;
    REQUIRE(decoder.build(descriptor, error));
    CHECK(decoder.mouseReportIds() == std::vector<uint8_t>{expected[i].mouseId});
  }
}

TEST_CASE("synthetic recordings: the replayed position follows the trajectory, saturation flagged where it lost",
          "[hid][recordings]") {
  const SyntheticTrajectory truth = loadTruth();
  // And the mouse that sends its buttons in a report of their own (Xiaomi layout): its buttons
  // as pressed, held across its X/Y reports (it is not in syntheticMice(), the bench's).
  std::vector<SyntheticMouse> mice = kf::test::syntheticMice();
  mice.push_back({"synthetic-250hz-split-buttons.hid", 250.0, 25.4 / 1000, 2047, 2});
  for (const SyntheticMouse& mouse : mice) {
    INFO(mouse.file);
    DeviceSpec spec;
    std::vector<TimedReport> reports;
    std::string error, warning;
    size_t skipped = 0;
    REQUIRE(loadReplayReports(dataPath(mouse.file), spec, reports, error, &skipped, &warning));
    CHECK(skipped == mouse.otherEvents);
    const double c = mouse.countMm;
    // The sensor rounds the position to a count: half a count each way, and 0.5 um for the
    // trajectory's interpolation between its samples.
    const double roundingMm = 0.5 * c + 0.0005;
    double x = 0, y = 0, lostMm = 0, previousTruthX = 0, previousTruthY = 0;
    size_t flagged = 0, withEverything = 0;
    for (const TimedReport& timed : reports) {
      const MouseReport& r = timed.report;
      const double t = timed.hostTimeS;
      INFO("report at " << t << " s: dx " << r.dxCounts << ", dy " << r.dyCounts);
      CHECK(r.buttons == truth.buttons(t));
      // A report without motion (the split mouse's buttons or wheel, sent before its poll's
      // motion report) says nothing of the position.
      if (r.dxCounts == 0 && r.dyCounts == 0) continue;
      x += r.dxCounts * c;
      y += r.dyCounts * c;
      // The movement since the last report, in counts, against what the report carried.
      const double movedX = (truth.xMm(t) - previousTruthX) / c, movedY = (truth.yMm(t) - previousTruthY) / c;
      previousTruthX = truth.xMm(t);
      previousTruthY = truth.yMm(t);
      const bool saturated = r.flags & kSaturated;
      if (saturated) {
        ++flagged;
        CHECK((std::abs(r.dxCounts) == mouse.limit || std::abs(r.dyCounts) == mouse.limit));
        CHECK(std::max(std::fabs(movedX), std::fabs(movedY)) > mouse.limit - 1);  // rounding: a count
        lostMm = truth.xMm(t) - x;
      } else {
        CHECK(std::max(std::fabs(movedX), std::fabs(movedY)) < mouse.limit + 1);  // nothing lost unflagged
      }
      // Where nothing was lost, the position is the trajectory's to the sensor's rounding;
      // after a loss, the trajectory's less what was lost.
      CHECK(std::fabs(truth.xMm(t) - lostMm - x) <= 2 * roundingMm);
      CHECK(std::fabs(truth.yMm(t) - y) <= roundingMm);
      if (r.dxCounts != 0 && r.dyCounts != 0 && r.buttons != 0) ++withEverything;
    }
    CHECK(withEverything > 0);  // reports with both axes and a button
    const bool saturates = mouse.rateHz == 125.0;
    CHECK((flagged > 0) == saturates);
    CHECK((warning.find("saturated") != std::string::npos) == saturates);
    if (saturates) {
      // Above 127 counts in 8 ms (333 mm/s) the excess is lost: the replay ends short, by what
      // the flagged reports lost, and says so.
      CHECK(truth.xMm(truth.durationS()) - x > 1.0);
      CHECK(warning.find(std::to_string(flagged) + " of " + std::to_string(reports.size())) != std::string::npos);
    } else {
      CHECK(std::fabs(truth.xMm(truth.durationS()) - x) <= roundingMm);
      CHECK(std::fabs(truth.yMm(truth.durationS()) - y) <= roundingMm);
    }
  }
}

TEST_CASE("synthetic recordings through the reconstruction: lag one report interval, error within rounding",
          "[hid][recordings]") {
  const SyntheticTrajectory truth = loadTruth();
  constexpr double kSampleRateHz = 48000.0;
  constexpr double kMotionStartS = 0.2;  // make_synthetic.py: still before
  for (const SyntheticMouse& mouse : kf::test::syntheticMice()) {
    INFO(mouse.file);
    const std::string path = dataPath(mouse.file);
    DeviceSpec spec;
    std::vector<TimedReport> reports;
    std::string error;
    REQUIRE(loadReplayReports(path, spec, reports, error));
    double firstSaturatedS = truth.durationS();
    for (const TimedReport& timed : reports)
      if (timed.report.flags & kSaturated) firstSaturatedS = std::min(firstSaturatedS, timed.hostTimeS);

    kf::test::SimRender render =
        kf::test::renderReplayAgainstTruth(path, mouse, truth, TrajectoryMode::Linear, kSampleRateHz);
    REQUIRE(render.renderedMm.size() > kSampleRateHz);
    const double intervalS = 1.0 / mouse.rateHz;
    CHECK(render.intervalS == Approx(intervalS));  // measured from the reports, the spec says 125 Hz
    const double endShortMm = truth.xMm(truth.durationS()) - render.renderedMm.back();
    // Up to the first saturated report (all of it at 1 and 8 kHz).
    render.truthMm.resize(static_cast<size_t>(firstSaturatedS * kSampleRateHz));
    render.renderedMm.resize(render.truthMm.size());
    const kf::test::LagFit fit = kf::test::fitLag(render, kSampleRateHz, kMotionStartS);
    // Linear interpolation runs one report interval behind by design; a report is taken at the
    // first audio sample at or after its time: within 2 samples (measured: 0 or 1).
    CHECK(std::fabs(fit.lagS - intervalS) <= 2.0 / kSampleRateHz);
    // Once the lag is removed: the sensor's rounding (half a count) plus linear interpolation's
    // error over one interval, |x''| T^2 / 8 with |x''| < 16000 mm/s^2 (the sweep's 20 mm x
    // (2 pi 4.5 Hz)^2), bound the error (measured RMS 0.017, 0.005, 0.0024 mm).
    const double boundMm = 0.5 * mouse.countMm + 16000.0 * intervalS * intervalS / 8;
    CHECK(fit.rmsErrorAtLagMm <= boundMm);
    if (firstSaturatedS < truth.durationS()) {
      // Past it the replay falls behind by what the saturated reports lost, and stays there.
      CHECK(endShortMm > 1.0);
    } else {
      CHECK(std::fabs(endShortMm) <= 0.5 * mouse.countMm + 1e-4);  // float output
    }
  }
}
