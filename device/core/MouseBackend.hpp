// MouseBackend: a source of mouse reports (simulator, replayed file, real HID mouse).
#pragma once

#include <string>

#include "core/spec/Report.hpp"
#include "core/threads/ThreadScheduling.hpp"

namespace kf {

class MouseBackend {
 public:
  virtual ~MouseBackend() = default;
  // Lets time run up to `untilTimeS` (the host's clock: seconds since the device was opened,
  // or audio time in lockstep) and writes at most `capacity` of the reports that arrived by
  // then, oldest first. Their deviceTimeS is the device's own clock (it may drift). Reports
  // that do not fit stay for the next call. Returns how many were written. One thread only.
  virtual int pollReports(double untilTimeS, MouseReport* out, int capacity) = 0;
  // False while the source is gone (a real mouse unplugged). Any non-realtime thread.
  virtual bool connected() const { return true; }
  // A line for kfStatus about the source itself (a real mouse: state, losses); empty for none.
  // Non-realtime threads only.
  virtual std::string statusLine() const { return {}; }
  // How the backend's own reader thread is scheduled; "not started" for backends without one.
  virtual ThreadScheduling readerScheduling() const { return {}; }
};

}  // namespace kf
