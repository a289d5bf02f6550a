// Every mode of the plugin's four UGens, as synths for FakeServer to play: each mode a unit of
// its own (an interpolation, a rate, an input that moves, a bad input, a buffer of each kind, a
// slot with or without a device), so that one run of the audio thread goes through them all.
#pragma once

#include <atomic>
#include <memory>

#include "FakeServer.hpp"
#include "Synth.hpp"

namespace kf::rules {

// What the chain's outputs showed, watched on the audio thread.
struct ChainWatch {
  std::atomic<float> largestXMm{0.f};     // FrictionMouseIn's x
  std::atomic<float> largestForceN{0.f};  // FrictionOut's output
  std::atomic<float> largestDrive{0.f};   // |FrictionDrive's output| (drivesSynth)
};

// FrictionMouseIn -> SpatialBufRd -> LoudnessToFriction -> FrictionOut on slot 0.
std::unique_ptr<Synth> chainSynth(FakeServer& server, ChainWatch& watch);
// FrictionMouseIn of slot 0: every interpolation, both rates, moving and bad inputs.
std::unique_ptr<Synth> mouseModesSynth(FakeServer& server);
// SpatialBufRd: every interpolation, position at both rates, keep, every kind of buffer.
std::unique_ptr<Synth> readersSynth(FakeServer& server);
// SpatialBufRd2D: every interpolation, both rates, the layout moving, every kind of buffer.
std::unique_ptr<Synth> surfacesSynth(FakeServer& server);
// SpeedGovernor: both rates, settings moving and bad.
std::unique_ptr<Synth> governorsSynth(FakeServer& server);
// LoudnessToFriction: every window, maxWindow and mapping mode, both rates.
std::unique_ptr<Synth> loudnessSynth(FakeServer& server);
// FrictionPattern: every kind, parameters moving and bad, position at both rates, fed by the puck.
std::unique_ptr<Synth> patternsSynth(FakeServer& server);
// FrictionOut: more writers of slot 0, force at both rates, bad forces and devices.
std::unique_ptr<Synth> writersSynth(FakeServer& server);
// FrictionDrive of slot 0 (watched), of slot 1 and of bad device inputs.
std::unique_ptr<Synth> drivesSynth(FakeServer& server, ChainWatch& watch);
// A reader and a writer of slot 1.
std::unique_ptr<Synth> slot1Synth(FakeServer& server);
// Units whose constructors run while slot 0 has a device.
std::unique_ptr<Synth> lateJoinersSynth(FakeServer& server);

}  // namespace kf::rules
