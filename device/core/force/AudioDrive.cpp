#include "core/force/AudioDrive.hpp"

#include <algorithm>
#include <limits>

namespace kf {

DeviceSpec AudioDrive::perSample(DeviceSpec spec, const DriveCircuit& circuit, double sampleRateHz) {
  // A frame is one sample: the slew limit allows maxForceSlewNPerS / sampleRate per sample.
  spec.forceFramePeriodS = 1.0 / sampleRateHz;
  // The circuit's declared safe current is one more hard limit on the drive.
  spec.maxDriveLevel = std::min(spec.maxDriveLevel, circuit.safeDriveLevel());
  return spec;
}

AudioDrive::AudioDrive(const DeviceSpec& spec, const DriveCircuit& circuit, double sampleRateHz)
    : circuit_(circuit), sampleRateHz_(sampleRateHz), safety_(perSample(spec, circuit, sampleRateHz)) {
  safety_.setCalibration(circuit.magnet);
}

void AudioDrive::process(const float* forceN, int numSamples, float* sampleOut) {
  // No frame time: ForceSafety then takes exactly one frame period (one sample) as elapsed.
  constexpr double kNoTime = std::numeric_limits<double>::quiet_NaN();
  const double safeDrive = circuit_.safeDriveLevel();
  for (int i = 0; i < numSamples; ++i) {
    safety_.applyFrame(ForceFrame{kNoTime, forceN[i], 0.0}, 0.0);
    // The limits above already hold the drive within the safe level; the clamp makes it a rule
    // of this function, whatever the table or the heat estimate did.
    const double drive = std::min(static_cast<double>(safety_.driveLevel()), safeDrive);
    sampleOut[i] = static_cast<float>(circuit_.sampleForDrive(drive));
  }
}

}  // namespace kf
