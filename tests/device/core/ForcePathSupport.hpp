// A ForceBackend that keeps every command and drive-off with its time, for the force path
// tests: the time the magnet went off is read from here.
#pragma once

#include <functional>
#include <mutex>
#include <vector>

#include "core/ForceBackend.hpp"

namespace kf::test {

class TimelineSink : public ForceBackend {
 public:
  struct Event {
    double timeS;  // the command's time, or the clock's at a drive-off
    float forceN;
    float drive;
    bool off;
  };

  // Where drive-offs take their time from (they carry none); default 0.
  void setClock(std::function<double()> clock) {
    std::lock_guard<std::mutex> lock(mutex_);
    clock_ = std::move(clock);
  }
  void commandForce(double timeS, float forceN) override { commandDrive(timeS, forceN, -1.0f); }
  void commandDrive(double timeS, float forceN, float drive) override {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back({timeS, forceN, drive, false});
  }
  void driveOff() override {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back({clock_ ? clock_() : 0.0, 0.0f, 0.0f, true});
  }
  std::vector<Event> events() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_;
  }
  std::vector<Event> commands() const {
    std::vector<Event> out;
    for (const Event& e : events())
      if (!e.off) out.push_back(e);
    return out;
  }
  std::vector<double> offTimes() const {
    std::vector<double> out;
    for (const Event& e : events())
      if (e.off) out.push_back(e.timeS);
    return out;
  }

 private:
  mutable std::mutex mutex_;
  std::function<double()> clock_;
  std::vector<Event> events_;
};

}  // namespace kf::test
