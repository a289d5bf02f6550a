// AudioDrive: a device's force (N) as the sample values of a DC-coupled audio output that drives
// the magnet through a current source (FrictionDrive). Each sample passes the board's safety
// path, ForceSafety, with a frame of one sample: non-finite to minimum, clamp, slew at the
// device's maxForceSlewNPerS per second of samples, the magnet table (N -> fraction of
// full-scale current), the hard limit min(maxDriveLevel, the circuit's safe current), heat
// derating; then DriveCircuit turns the drive level into volts and a sample value. So the audio
// drive keeps every rule the board keeps, per sample instead of per 1 ms frame.
// Built (allocating) outside the audio thread; process() and off() allocate nothing.
#pragma once

#include "core/force/DriveCircuit.hpp"
#include "core/force/ForceSafety.hpp"
#include "core/spec/DeviceSpec.hpp"

namespace kf {

class AudioDrive {
 public:
  AudioDrive(const DeviceSpec& spec, const DriveCircuit& circuit, double sampleRateHz);

  // One block: forceN[i] -> sampleOut[i], sample by sample.
  void process(const float* forceN, int numSamples, float* sampleOut);
  // The magnet off (no writer, a gap in the blocks): the next sample slews up from the minimum.
  void off() { safety_.resetToOff(); }
  // This chain replaces `previous` on the same coil (a reload): it goes on from its heat and
  // slew, so a reload neither cools the coil nor restarts the slew. No allocation (RT stage).
  void continueFrom(const AudioDrive& previous) {
    safety_.continueFrom(previous.safety_, previous.circuit_.fullScaleCurrentA / circuit_.fullScaleCurrentA);
  }

  // The force the last sample commands (after the limits) and its drive level.
  float commandedForceN() const { return safety_.commandedForceN(); }
  float driveLevel() const { return safety_.driveLevel(); }
  const DriveCircuit& circuit() const { return circuit_; }
  double sampleRateHz() const { return sampleRateHz_; }

 private:
  static DeviceSpec perSample(DeviceSpec spec, const DriveCircuit& circuit, double sampleRateHz);

  DriveCircuit circuit_;
  double sampleRateHz_;
  ForceSafety safety_;
};

}  // namespace kf
