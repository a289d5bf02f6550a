#include "UgenModes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace kf::rules {

namespace {

constexpr int ar = calc_FullRate;
constexpr int kr = calc_BufRate;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

Input c(float value) { return Input::constant(value); }

// A control that holds `a` for 20 blocks, then `b` for 20, and so on: a value that changes.
Input alternating(float a, float b) {
  return Input::control([a, b](int64_t block) { return (block / 20) % 2 == 0 ? a : b; });
}

// A position (mm) sweeping 0..100 mm and back every 4 s, at audio or control rate.
float sweepMm(double timeS) { return static_cast<float>(50.0 - 50.0 * std::cos(timeS * 3.14159265 / 2.0)); }
Input sweepAr() {
  return Input::audio([](int64_t sample) { return sweepMm(sample / FakeServer::kSampleRate); });
}
Input sweepKr() {
  return Input::control(
      [](int64_t block) { return sweepMm(block * FakeServer::kBlockSamples / FakeServer::kSampleRate); });
}

// A tone whose loudness swells and fades over 2 s (loudness to friction sweeps its range).
Input toneAr() {
  return Input::audio([](int64_t sample) {
    const double t = sample / FakeServer::kSampleRate;
    return static_cast<float>(std::sin(t * 2.0 * 3.14159265) * std::sin(t * 2764.6));
  });
}

}  // namespace

// FrictionMouseIn -> SpatialBufRd -> LoudnessToFriction -> FrictionOut on slot 0, as the paper's
// patch: every UGen fed by the one before.
std::unique_ptr<Synth> chainSynth(FakeServer& server, ChainWatch& watch) {
  auto synth = server.newSynth("chain");
  Unit* mouse = synth->add(server.unitDef("FrictionMouseIn"), ar, {c(0), c(0), c(1)}, 4, "device 0, linear");
  Unit* reader =
      synth->add(server.unitDef("SpatialBufRd"), ar, {c(0), Input::from(synth->out(mouse, 0)), c(20), c(0), c(4), c(0)},
                 1, "buffer 0, cubic, at the puck");
  Unit* loudness =
      synth->add(server.unitDef("LoudnessToFriction"), ar,
                 {Input::from(synth->out(reader, 0)), c(0.001f), c(-30), c(0), c(0.2f), c(2), c(1), c(0.05f)}, 1,
                 "the paper's mapping");
  Unit* out = synth->add(server.unitDef("FrictionOut"), ar, {c(0), Input::from(synth->out(loudness, 0))}, 1,
                         "device 0, force from LoudnessToFriction");
  const float* x = synth->out(mouse, 0)->mBuffer;
  const float* force = synth->out(out, 0)->mBuffer;
  synth->watch([&watch, x, force] {
    watch.largestXMm.store(std::max(watch.largestXMm.load(), std::fabs(x[FakeServer::kBlockSamples - 1])));
    watch.largestForceN.store(std::max(watch.largestForceN.load(), force[FakeServer::kBlockSamples - 1]));
  });
  return synth;
}

// Every interpolation at audio and control rate, a moving origin, and the bad inputs; and
// FrictionButtons of slot 0 at both rates and of bad slots.
std::unique_ptr<Synth> mouseModesSynth(FakeServer& server) {
  auto synth = server.newSynth("mouse modes");
  const auto& mouse = server.unitDef("FrictionMouseIn");
  synth->add(mouse, ar, {c(0), c(0), c(0)}, 4, "device 0, hold");
  synth->add(mouse, ar, {c(0), c(0), c(2)}, 4, "device 0, predictive");
  synth->add(mouse, kr, {c(0), c(0), c(1)}, 4, "device 0, linear");
  synth->add(mouse, kr, {c(0), c(0), c(2)}, 4, "device 0, predictive");
  synth->add(mouse, ar, {c(0), alternating(0, 25), alternating(0, 2)}, 4, "device 0, origin and mode moving");
  synth->add(mouse, ar, {c(0), c(kNaN), c(1)}, 4, "device 0, origin NaN");
  synth->add(mouse, ar, {c(0), c(0), c(kNaN)}, 4, "device 0, interpolation NaN");
  synth->add(mouse, ar, {c(-1), c(0), c(1)}, 4, "device -1");
  synth->add(mouse, ar, {c(kNaN), c(0), c(1)}, 4, "device NaN");
  synth->add(mouse, kr, {c(16), c(0), c(1)}, 4, "device 16");
  const auto& buttons = server.unitDef("FrictionButtons");
  synth->add(buttons, kr, {c(0)}, 3, "buttons of device 0, control rate");
  synth->add(buttons, ar, {c(0)}, 3, "buttons of device 0, audio rate");
  synth->add(buttons, kr, {c(kNaN)}, 3, "buttons of device NaN");
  synth->add(buttons, kr, {c(5)}, 3, "buttons of device 5 (none open)");
  return synth;
}

// Interpolations 1, 2 and 4 with the position at audio and at control rate, with and without
// keep (samplesPerMm and origin changing), the buffers of every kind and the bad inputs.
std::unique_ptr<Synth> readersSynth(FakeServer& server) {
  auto synth = server.newSynth("readers");
  const auto& reader = server.unitDef("SpatialBufRd");
  for (int interpolation : {1, 2, 4}) {
    const std::string mode = "interpolation " + std::to_string(interpolation);
    const auto code = static_cast<float>(interpolation);
    synth->add(reader, ar, {c(0), sweepAr(), c(20), c(0), c(code), c(0)}, 1, mode + ", position ar");
    synth->add(reader, kr, {c(0), sweepKr(), c(20), c(0), c(code), c(0)}, 1, mode + ", position kr");
    synth->add(reader, ar, {c(0), sweepAr(), alternating(10, 40), alternating(0, 5), c(code), c(1)}, 1,
               mode + ", position ar, keep");
    synth->add(reader, kr, {c(0), sweepKr(), alternating(10, 40), alternating(0, 5), c(code), c(1)}, 1,
               mode + ", position kr, keep");
  }
  synth->add(reader, ar, {c(0), sweepAr(), c(20), c(0), c(4)}, 1, "no keep input");
  synth->add(reader, ar, {c(1), sweepAr(), c(20), c(0), c(4), c(0)}, 2, "stereo buffer");
  synth->add(reader, ar, {c(FakeServer::kNumBuffers), sweepAr(), c(20), c(0), c(2), c(0)}, 1, "local buffer");
  synth->add(reader, ar, {c(1), sweepAr(), c(20), c(0), c(4), c(0)}, 1, "channel mismatch");
  synth->add(reader, ar, {c(2), sweepAr(), c(20), c(0), c(4), c(0)}, 1, "buffer not allocated");
  synth->add(reader, ar, {alternating(0, 2), sweepAr(), c(20), c(0), c(4), c(0)}, 1, "buffer changing");
  synth->add(reader, ar, {c(99), sweepAr(), c(20), c(0), c(4), c(0)}, 1, "bufnum 99");
  synth->add(reader, ar, {c(kNaN), sweepAr(), c(20), c(0), c(4), c(0)}, 1, "bufnum NaN");
  synth->add(reader, ar, {c(0), sweepAr(), alternating(kNaN, 10), c(0), c(4), c(1)}, 1, "samplesPerMm NaN, keep");
  synth->add(reader, ar, {c(0), sweepAr(), c(0), c(0), c(4), c(0)}, 1, "samplesPerMm 0");
  synth->add(reader, ar, {c(0), sweepAr(), c(20), c(kInf), c(4), c(0)}, 1, "origin inf");
  synth->add(reader, ar, {c(0), sweepAr(), c(20), c(0), c(3), c(0)}, 1, "interpolation 3");
  synth->add(
      reader, ar,
      {c(0), Input::audio([](int64_t sample) { return sample % 100 < 50 ? kNaN : 10.f; }), c(20), c(0), c(4), c(1)}, 1,
      "position NaN at times, keep");
  return synth;
}

// SpatialBufRd2D: every interpolation, positions at both rates (a path crossing the matrix's
// borders), the layout moving, every kind of buffer and the bad inputs. Buffer 0 (48000 mono
// frames) is read as 240 rows of 200.
std::unique_ptr<Synth> surfacesSynth(FakeServer& server) {
  auto synth = server.newSynth("surfaces");
  const auto& surface = server.unitDef("SpatialBufRd2D");
  auto add = [&](int rate, Input bufnum, Input x, Input y, Input width, Input spmX, Input spmY, Input originX,
                 Input originY, float interpolation, const std::string& what) {
    synth->add(surface, rate, {bufnum, x, y, width, spmX, spmY, originX, originY, c(interpolation)}, 1, what);
  };
  for (int interpolation : {1, 2, 4}) {
    const std::string mode = "interpolation " + std::to_string(interpolation);
    const auto code = static_cast<float>(interpolation);
    add(ar, c(0), sweepAr(), sweepAr(), c(200), c(2), c(2.4f), c(-5), c(-5), code, mode + ", x and y ar");
    add(kr, c(0), sweepKr(), sweepKr(), c(200), c(2), c(2.4f), c(-5), c(-5), code, mode + ", x and y kr");
    add(ar, c(0), sweepAr(), c(10), alternating(200, 100), alternating(2, 5), alternating(1, 3), alternating(0, 9),
        alternating(0, -3), code, mode + ", layout moving");
  }
  add(ar, c(FakeServer::kNumBuffers), sweepAr(), sweepAr(), c(10), c(2), c(2), c(0), c(0), 4, "local buffer");
  add(ar, c(1), sweepAr(), sweepAr(), c(200), c(2), c(2), c(0), c(0), 4, "stereo buffer");
  add(ar, c(2), sweepAr(), sweepAr(), c(200), c(2), c(2), c(0), c(0), 4, "buffer not allocated");
  add(ar, alternating(0, 3), sweepAr(), sweepAr(), c(64), c(2), c(2), c(0), c(0), 4, "buffer changing");
  add(ar, c(kNaN), sweepAr(), sweepAr(), c(200), c(2), c(2), c(0), c(0), 4, "bufnum NaN");
  add(ar, c(0), sweepAr(), sweepAr(), alternating(0, 1e9f), c(2), c(2), c(0), c(0), 4, "width 0 and too large");
  add(ar, c(0), sweepAr(), sweepAr(), c(kNaN), c(2), c(2), c(0), c(0), 4, "width NaN");
  add(ar, c(0), sweepAr(), sweepAr(), c(200), alternating(kNaN, 2), c(-1), c(kInf), alternating(0, kNaN), 4,
      "samplesPerMm and origins bad");
  add(ar, c(0), Input::audio([](int64_t sample) { return sample % 100 < 50 ? kNaN : 10.f; }), sweepAr(), c(200), c(2),
      c(2), c(0), c(0), 2, "x NaN at times");
  return synth;
}

// SpeedGovernor: speeds at both rates, settings moving and bad.
std::unique_ptr<Synth> governorsSynth(FakeServer& server) {
  auto synth = server.newSynth("governors");
  const auto& governor = server.unitDef("SpeedGovernor");
  auto speedAr = Input::audio([](int64_t sample) { return static_cast<float>(sample % 4800) * 0.05f; });
  synth->add(governor, ar, {speedAr, speedAr, c(80), c(0.01f), c(0.14f), c(1.4f)}, 1, "speeds ar");
  synth->add(governor, kr, {sweepKr(), sweepKr(), c(80), c(0.01f), c(0.14f), c(1.4f)}, 1, "speeds kr");
  synth->add(governor, ar,
             {speedAr, c(0), alternating(20, 200), alternating(0.001f, 0.1f), alternating(0.1f, 0.3f),
              alternating(1.4f, 0.05f)},
             1, "settings moving, hiForce below loForce at times");
  synth->add(governor, ar, {speedAr, c(kNaN), alternating(kNaN, -1), c(kInf), c(kNaN), c(-kInf)}, 1, "bad inputs");
  return synth;
}

// The window and maxWindow modes (paper's, moving, bad, beyond the limit: the history's
// allocation fails), the mapping moving every block and bad, and control rate.
std::unique_ptr<Synth> loudnessSynth(FakeServer& server) {
  auto synth = server.newSynth("loudness");
  const auto& loudness = server.unitDef("LoudnessToFriction");
  auto add = [&](Input window, Input loDb, Input hiDb, Input loForce, Input hiForce, Input ref, float maxWindow,
                 const char* what) {
    synth->add(loudness, ar, {toneAr(), window, loDb, hiDb, loForce, hiForce, ref, c(maxWindow)}, 1, what);
  };
  add(c(0.001f), c(-30), c(0), c(0.2f), c(2), c(1), 0.05f, "the paper's mapping");
  add(alternating(0.001f, 0.02f), c(-30), c(0), c(0.2f), c(2), c(1), 0.05f, "window moving");
  add(c(kNaN), c(-30), c(0), c(0.2f), c(2), c(1), 0.05f, "window NaN");
  add(c(0), c(-30), c(0), c(0.2f), c(2), c(1), 0.05f, "window 0");
  add(c(1), c(-30), c(0), c(0.2f), c(2), c(1), 0.05f, "window beyond maxWindow");
  add(c(0.001f), c(-30), c(0), c(0.2f), c(2), c(1), kNaN, "maxWindow NaN");
  add(c(0.5f), c(-30), c(0), c(0.2f), c(2), c(1), 1.f, "maxWindow 1 s");
  add(c(0.001f), c(-30), c(0), c(0.2f), c(2), c(1), 1e9f, "maxWindow beyond the limit, RT memory short");
  add(c(0.001f), c(-30), Input::control([](int64_t block) { return -static_cast<float>(block % 7); }), c(0.2f), c(2),
      c(1), 0.05f, "hiDb moving every block");
  add(c(0.001f), c(kNaN), c(kInf), c(-1), c(kNaN), c(0), 0.05f, "bad mapping");
  add(c(0.001f), c(0), c(-30), c(2), c(0.2f), c(1), 0.05f, "mapping reversed");
  synth->add(loudness, kr, {sweepKr(), c(0.01f), c(-30), c(40), c(0.2f), c(2), c(1), c(0.05f)}, 1, "control rate");
  synth->add(loudness, ar,
             {Input::audio([](int64_t sample) { return sample % 3 == 0 ? kNaN : (sample % 3 == 1 ? kInf : 0.5f); }),
              c(0.001f), c(-30), c(0), c(0.2f), c(2), c(1), c(0.05f)},
             1, "in NaN and inf");
  return synth;
}

// Every kind of FrictionPattern fed by slot 0's puck, then by a sweep at both rates, with its
// parameters moving every 20 blocks (phase-continuous changes, the texture's crossfade), bad
// parameters and forces, an unknown kind, and its force into FrictionOut.
std::unique_ptr<Synth> patternsSynth(FakeServer& server) {
  auto synth = server.newSynth("patterns");
  const auto& pattern = server.unitDef("FrictionPattern");
  Unit* mouse = synth->add(server.unitDef("FrictionMouseIn"), ar, {c(0), c(0), c(1)}, 4, "device 0, linear");
  const Input puck = Input::from(synth->out(mouse, 0));
  const float kinds[][3] = {{1, 0.5f, 0.1f}, {4, 2, 0}, {3, 0.5f, 0}, {0.5f, 3, 7}, {100, 0, 0}, {5, 2, 0}};
  for (int kind = 0; kind < 6; ++kind) {
    const auto* p = kinds[kind];
    const std::string k = "kind " + std::to_string(kind);
    synth->add(pattern, ar, {c(kind), puck, c(0.14f), c(0.5f), c(1), c(p[0]), c(p[1]), c(p[2])}, 1,
               k + ", at the puck");
    synth->add(pattern, ar,
               {c(kind), sweepAr(), c(0.14f), c(0.5f), alternating(0, 1), alternating(p[0], 2 * p[0] + 0.1f),
                alternating(p[1], p[1] + 1), alternating(p[2], p[2] + 1)},
               1, k + ", parameters moving");
    synth->add(pattern, kr, {c(kind), sweepKr(), c(0.14f), c(0.5f), c(1), c(p[0]), c(p[1]), c(p[2])}, 1,
               k + ", control rate");
    synth->add(pattern, ar, {c(kind), sweepAr(), c(kNaN), c(-1), c(1), c(kNaN), c(kInf), c(-kInf)}, 1,
               k + ", bad parameters and forces");
  }
  synth->add(pattern, ar, {c(6), sweepAr(), c(0.14f), c(0.5f), c(0), toneAr(), c(1), c(0)}, 1, "slope of a tone");
  synth->add(pattern, ar, {c(6), sweepAr(), c(0.14f), c(0.5f), c(0), sweepKr(), c(kNaN), c(0)}, 1,
             "slope, height kr, fullSlope NaN");
  // bumps2D (kind 7): y as a ninth input, at the puck, both rates, moving, bad, and absent.
  const Input puckY = Input::from(synth->out(mouse, 1));
  synth->add(pattern, ar, {c(7), puck, c(0.14f), c(0.5f), c(1), c(4), c(3), c(2), puckY}, 1, "bumps2D at the puck");
  synth->add(pattern, ar,
             {c(7), sweepAr(), c(0.14f), c(0.5f), alternating(0, 1), alternating(4, 9), alternating(3, 4),
              alternating(2, 3), toneAr()},
             1, "bumps2D, parameters moving");
  synth->add(pattern, kr, {c(7), sweepKr(), c(0.14f), c(0.5f), c(1), c(4), c(3), c(2), sweepKr()}, 1,
             "bumps2D, control rate");
  synth->add(pattern, ar, {c(7), sweepAr(), c(kNaN), c(-1), c(1), c(kNaN), c(kInf), c(-kInf), c(kNaN)}, 1,
             "bumps2D, bad parameters, forces and y");
  synth->add(pattern, ar, {c(7), sweepAr(), c(0.14f), c(0.5f), c(1), c(4), c(3), c(2)}, 1, "bumps2D, no y");
  // texture2D (kind 8): y as a ninth input, as bumps2D's; parameters moving runs its crossfades.
  synth->add(pattern, ar, {c(8), puck, c(0.14f), c(0.5f), c(1), c(0.5f), c(3), c(7), puckY}, 1,
             "texture2D at the puck");
  synth->add(pattern, ar,
             {c(8), sweepAr(), c(0.14f), c(0.5f), alternating(0, 1), alternating(0.5f, 2), alternating(3, 5),
              alternating(7, 8), toneAr()},
             1, "texture2D, parameters moving");
  synth->add(pattern, kr, {c(8), sweepKr(), c(0.14f), c(0.5f), c(1), c(0.5f), c(3), c(7), sweepKr()}, 1,
             "texture2D, control rate");
  synth->add(pattern, ar, {c(8), sweepAr(), c(kNaN), c(-1), c(1), c(kNaN), c(kInf), c(-kInf), c(kNaN)}, 1,
             "texture2D, bad parameters, forces and y");
  synth->add(pattern, ar, {c(8), sweepAr(), c(0.14f), c(0.5f), c(1), c(0.5f), c(3), c(7)}, 1, "texture2D, no y");
  synth->add(pattern, ar, {c(kNaN), puck, c(0.14f), c(0.5f), c(1), c(1), c(0.5f), c(0.1f)}, 1, "kind NaN");
  Unit* grating = synth->add(pattern, ar, {c(0), puck, c(0.14f), c(0.5f), c(1), c(0.2f), c(0.5f), c(0.02f)}, 1,
                             "a grating under the puck");
  synth->add(server.unitDef("FrictionOut"), ar, {c(0), Input::from(synth->out(grating, 0))}, 1,
             "device 0, force from FrictionPattern");
  return synth;
}

// More writers of slot 0: force at audio and control rate, bad forces, fades at audio and control
// rate (NaN and above 1 too), bad device inputs, and one moving between slots 0 and 1.
std::unique_ptr<Synth> writersSynth(FakeServer& server) {
  auto synth = server.newSynth("writers");
  const auto& out = server.unitDef("FrictionOut");
  synth->add(out, ar, {c(0), Input::audio([](int64_t sample) { return 0.5f + 0.4f * std::sin(sample * 0.001f); })}, 1,
             "device 0, force ar");
  synth->add(out, ar, {c(0), alternating(0.3f, 1.5f)}, 1, "device 0, force kr");
  synth->add(out, kr, {c(0), alternating(0.3f, 1.5f)}, 1, "device 0");
  synth->add(out, ar, {c(0), Input::audio([](int64_t sample) { return sample % 2 == 0 ? kNaN : kInf; })}, 1,
             "device 0, force NaN and inf");
  synth->add(out, ar, {c(0), c(0.9f), Input::audio([](int64_t sample) { return (sample % 480) / 479.0f; })}, 1,
             "device 0, fade ar");
  synth->add(out, kr, {c(0), c(0.9f), alternating(kNaN, 1.5f)}, 1, "device 0, fade kr NaN and above 1");
  synth->add(out, ar, {alternating(0, 1), c(1)}, 1, "device moving between 0 and 1");
  synth->add(out, ar, {c(-1), c(1)}, 1, "device -1");
  synth->add(out, ar, {c(kNaN), c(1)}, 1, "device NaN");
  return synth;
}

// FrictionDrive: slot 0 (its output watched), slot 1 and bad device inputs.
std::unique_ptr<Synth> drivesSynth(FakeServer& server, ChainWatch& watch) {
  auto synth = server.newSynth("drives");
  const auto& drive = server.unitDef("FrictionDrive");
  Unit* slot0 = synth->add(drive, ar, {c(0)}, 1, "device 0");
  synth->add(drive, ar, {c(0)}, 1, "device 0, a second one");
  synth->add(drive, ar, {alternating(0, 1)}, 1, "device moving between 0 and 1");
  synth->add(drive, ar, {c(kNaN)}, 1, "device NaN");
  const float* out = synth->out(slot0, 0)->mBuffer;
  synth->watch([&watch, out] {
    watch.largestDrive.store(std::max(watch.largestDrive.load(), std::fabs(out[FakeServer::kBlockSamples - 1])));
  });
  return synth;
}

// The replay device's slot: a reader and a writer.
std::unique_ptr<Synth> slot1Synth(FakeServer& server) {
  auto synth = server.newSynth("slot 1");
  synth->add(server.unitDef("FrictionMouseIn"), ar, {c(1), c(0), c(2)}, 4, "device 1, predictive");
  synth->add(server.unitDef("FrictionMouseIn"), kr, {c(1), c(0), c(1)}, 4, "device 1, linear");
  synth->add(server.unitDef("FrictionButtons"), kr, {c(1)}, 3, "buttons of device 1");
  synth->add(server.unitDef("FrictionOut"), ar, {c(1), c(0.8f)}, 1, "device 1, constant force");
  return synth;
}

// Units constructed while the device is open (their constructors see it).
std::unique_ptr<Synth> lateJoinersSynth(FakeServer& server) {
  auto synth = server.newSynth("late joiners");
  synth->add(server.unitDef("FrictionMouseIn"), ar, {c(0), c(0), c(1)}, 4, "device 0, linear");
  synth->add(server.unitDef("FrictionOut"), ar, {c(0), c(1)}, 1, "device 0, constant force");
  synth->add(server.unitDef("LoudnessToFriction"), ar,
             {toneAr(), c(0.001f), c(-30), c(0), c(0.2f), c(2), c(1), c(0.05f)}, 1, "the paper's mapping");
  return synth;
}

}  // namespace kf::rules
