// SimDevice: a whole simulated friction device — scripted hand (along x or on the surface) or an
// exploring participant's push, puck
// with Coulomb friction,
// lagging magnet and mouse sensor — stepped with a fixed step by advanceTo(). It is both the
// mouse backend and the force backend. Deterministic: the same calls give the same reports
// bit for bit; advanceTo() never allocates. Not thread-safe: drive it from one thread (the
// device thread or, in lockstep, the audio thread) and read the truth accessors there.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "core/ForceBackend.hpp"
#include "core/MouseBackend.hpp"
#include "core/spec/DeviceSpec.hpp"
#include "sim/ExploringHand.hpp"
#include "sim/HandScript.hpp"
#include "sim/MagnetModel.hpp"
#include "sim/MouseSensorModel.hpp"
#include "sim/PuckModel.hpp"
#include "sim/SimParams.hpp"

namespace kf {

class SimDevice : public MouseBackend, public ForceBackend {
 public:
  static constexpr int kReportBufferCapacity = 4096;

  SimDevice(const DeviceSpec& spec, const SimParams& params, const HandScript& hand);

  // Steps the simulation up to `timeS` (true time), in whole steps of params.stepS.
  void advanceTo(double timeS);

  int pollReports(double untilTimeS, MouseReport* out, int capacity) override;
  // The next pollReports throws, as a driver that lost its device would: for rehearsing what a
  // study or a performance does when its device fails (kfSimFail). From any thread.
  void failNextPoll() { failNextPoll_.store(true, std::memory_order_release); }
  // A held hand (SimParams::handHeld) starts its script at the next step: the scene's movement
  // starts with what the scene plays (kfSimRelease). From any thread; no effect on a free hand.
  void releaseHand() { releaseRequested_.store(true, std::memory_order_release); }
  bool handIsHeld() const { return handHeld_; }
  // Advances to timeS first, so the command takes effect from then on (late commands: now).
  void commandForce(double timeS, float forceN) override;
  void driveOff() override;

  // Truth, for tests and benchmarks.
  double timeS() const { return static_cast<double>(stepIndex_) * params_.stepS; }
  double positionMm() const { return puck_.positionM() * 1000.0; }
  double speedMmPerS() const { return puck_.speedMPerS() * 1000.0; }
  double frictionN() const { return magnet_.forceN(); }  // the magnet's actual force
  double commandedForceN() const { return magnet_.commandedN(); }
  double positionYMm() const { return puck_.positionYM() * 1000.0; }
  double speedYMmPerS() const { return puck_.speedYMPerS() * 1000.0; }
  double handForceN() const { return handForceN_; }    // last push on the puck (along x)
  double handForceYN() const { return handForceYN_; }  // and along y
  HandTarget handTarget() const { return hand_.at(handTimeS(timeS())); }
  uint64_t droppedReports() const { return sensor_.droppedReports(); }
  uint64_t bufferOverflows() const { return bufferOverflows_; }  // reports nobody polled
  const DeviceSpec& spec() const { return spec_; }
  const SimParams& params() const { return params_; }

 private:
  void step();
  struct Push {
    double xN = 0.0, yN = 0.0;
  };
  Push handPush(double timeS) const;
  double handTimeS(double timeS) const { return timeS - handStartS_; }  // the script's time
  void storeReport(const MouseReport& report);

  DeviceSpec spec_;
  SimParams params_;
  HandTrajectory hand_;
  bool exploring_;  // the hand is a participant (ExploringHand), not a script
  ExploringHand explorer_;
  PuckModel puck_;
  MagnetModel magnet_;
  MouseSensorModel sensor_;
  int64_t stepIndex_ = 0;
  double handForceN_ = 0.0;
  double handForceYN_ = 0.0;
  // Reports made but not yet polled; deviceTimeS order.
  std::vector<MouseReport> buffer_;
  int bufferHead_ = 0;
  int bufferCount_ = 0;
  uint64_t bufferOverflows_ = 0;
  std::atomic<bool> failNextPoll_{false};
  bool handHeld_;
  double handStartS_ = 0.0;  // the device time the hand's script starts at
  std::atomic<bool> releaseRequested_{false};
};

}  // namespace kf
