// ReplayBackend: plays recorded reports back as a MouseBackend, each at the host time it was
// received — from our own kf-session recordings or from hid-recorder files (decoded through
// the file's report descriptor; counts stay in the mouse's own counts, spec.countMm scales).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "DeviceSpec.hpp"
#include "ForceBackend.hpp"
#include "MouseBackend.hpp"
#include "SessionFile.hpp"

namespace kf {

class ReplayBackend : public MouseBackend {
 public:
  explicit ReplayBackend(std::vector<TimedReport> reports) : reports_(std::move(reports)) {}

  int pollReports(double untilTimeS, MouseReport* out, int capacity) override;

  size_t reportCount() const { return reports_.size(); }
  bool isFinished() const { return next_ >= reports_.size(); }

 private:
  std::vector<TimedReport> reports_;
  size_t next_ = 0;
};

// Force side of a replayed device: counts what it is told (no magnet). Readable from any
// thread.
class CountingForceSink : public ForceBackend {
 public:
  void commandForce(double timeS, float forceN) override;
  void driveOff() override;

  uint64_t commands() const { return commands_.load(std::memory_order_relaxed); }
  uint64_t driveOffs() const { return driveOffs_.load(std::memory_order_relaxed); }
  float lastForceN() const { return lastForceN_.load(std::memory_order_relaxed); }
  double lastTimeS() const { return lastTimeS_.load(std::memory_order_relaxed); }

 private:
  std::atomic<uint64_t> commands_{0};
  std::atomic<uint64_t> driveOffs_{0};
  std::atomic<float> lastForceN_{0.0f};
  std::atomic<double> lastTimeS_{0.0};
};

// The reports of a file, kf-session or hid-recorder (told apart by their first line).
// `spec` becomes the session file's header spec for kf-session files and stays as given
// for hid-recorder files. `skippedEvents` counts hid events that are not mouse reports.
// Missing, unreadable, empty, special (FIFO, device) files and directories are refused before
// reading, each with its own message. `warning` receives what was loaded despite a problem
// (a last line cut mid-way).
bool loadReplayReports(const std::string& path, DeviceSpec& spec, std::vector<TimedReport>& out, std::string& error,
                       size_t* skippedEvents = nullptr, std::string* warning = nullptr);

}  // namespace kf
