// ReplayBackend: plays recorded reports back as a MouseBackend, each at the host time it was
// received — from our own kf-session recordings or from hid-recorder files (decoded through
// the file's report descriptor; counts stay in the mouse's own counts, spec.countMm scales).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/MouseBackend.hpp"
#include "core/files/SessionFile.hpp"
#include "core/spec/DeviceSpec.hpp"

namespace kf {

// How a recording is played for live use. The recorded spec still applies (counts, update
// rate): only the timing changes.
struct ReplayOptions {
  double startS = 0.0;    // file time to start at (reports before it are not played)
  bool skipIdle = false;  // start one update interval before the first report that moves
  bool loop = false;      // at the end, start again (the position carries on accumulating)
  double rate = 1.0;      // 2: twice as fast (same path, speeds doubled)

  // Replay settings by name (startS, skipIdle, loop, rate); false for another key or a value
  // outside its bounds (SettingBounds), with `error`, if given, saying which.
  bool applyOverride(std::string_view key, double value, std::string* error = nullptr);
};

class ReplayBackend : public MouseBackend {
 public:
  explicit ReplayBackend(std::vector<TimedReport> reports, const ReplayOptions& options = {},
                         double updateRateHz = 125.0);

  int pollReports(double untilTimeS, MouseReport* out, int capacity) override;

  size_t reportCount() const { return reports_.size(); }
  bool isFinished() const { return !options_.loop && next_ >= reports_.size(); }
  // The file time the replay starts at (after startS / skipIdle).
  double startFileS() const { return startFileS_; }

 private:
  // Host (release) and device times of report i in the current pass, on the replay's clock.
  double replayTimeS(double fileTimeS) const { return (fileTimeS - startFileS_) / options_.rate + passOffsetS_; }

  std::vector<TimedReport> reports_;
  ReplayOptions options_;
  size_t first_ = 0;  // the first report played in every pass
  size_t next_ = 0;
  double startFileS_ = 0.0;
  double periodFileS_ = 0.0;  // one pass, in file time
  double passOffsetS_ = 0.0;  // replay time at which the current pass started
};

// The reports of a file, kf-session or hid-recorder (told apart by their first line).
// `spec` becomes the session file's header spec for kf-session files and stays as given
// for hid-recorder files. `skippedEvents` counts hid events that are not mouse reports; a hid
// report with a delta at its field's logical limit carries kSaturated.
// Missing, unreadable, empty, special (FIFO, device) files and directories are refused before
// reading, each with its own message. `warning` receives what was loaded despite a problem
// (a last line cut mid-way, saturated reports).
bool loadReplayReports(const std::string& path, DeviceSpec& spec, std::vector<TimedReport>& out, std::string& error,
                       size_t* skippedEvents = nullptr, std::string* warning = nullptr);

}  // namespace kf
