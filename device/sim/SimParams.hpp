// SimParams: the simulated hand, puck and sensor imperfections of SimDevice, settable by key
// like DeviceSpec so sclang can pass them as overrides.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace kf {

struct SimParams {
  // Hand: a spring-damper pulling the puck towards the scripted target, a soft "intent"
  // rather than a stiff servo. With the defaults a 100 mm/s target is followed at 100 mm/s
  // with 7 mm lag at 0.14 N; at 0.45 N it needs 15.5 mm more lag, so a fragment with that
  // friction is crossed markedly more slowly (6 mm: 3x, 48 mm: 1.3x the time at 100 mm/s),
  // as the pilot's subjects felt "bound to slower movements".
  double handStiffnessNPerM = 20.0;
  double handDampingNSPerM = 2.0;  // damping ratio 0.71 with the default mass: no ringing
  double handMaxForceN = 1.5;      // a fingertip push; above maxForceN so the puck never jams
  double puckMassKg = 0.1;
  double stepS = 1e-4;  // fixed integration step
  // 1: the hand rests on the puck without pushing until released (SimDevice::releaseHand), and
  // its script's time starts then, so that a scene's movement starts with what it plays.
  double handHeld = 0.0;

  // Sensor imperfections (all off by default).
  double reportJitterS = 0.0;    // standard deviation of report times, clipped to +-0.45 period
  double dropProbability = 0.0;  // each report is lost with this probability
  double clockDriftPpm = 0.0;    // device timestamps = true time * (1 + ppm * 1e-6)
  uint64_t seed = 1;             // of jitter and drops
  std::vector<std::pair<double, double>> liftIntervalsS;  // (start, end), true time

  // Sets a numeric field by its member name (and "liftStartS"/"liftEndS" pairs: a
  // liftStartS appends an interval, the following liftEndS closes it). False on unknown keys
  // or values outside their bounds (SettingBounds); `error`, if given, says which.
  bool applyOverride(std::string_view key, double value, std::string* error = nullptr);
  // True when every field is within its bounds (SettingBounds); `error` says which is not.
  bool isValid(std::string* error = nullptr) const;
};

}  // namespace kf
