// The audio-thread rules (ARCHITECTURE.md, "Threads and the audio-thread rule") on the real
// plugin: the built plugin is loaded into a stand-in for scsynth (audio_rules/FakeServer) and its
// four UGens run block after block on an audio thread, in every mode they have, while the
// plugin's own commands open a simulated and a replay device, record, query, add a board, hand a
// slot over, close devices and are refused, their RT parts on that audio thread between blocks
// (scsynth runs plugin commands there). Every call the audio thread makes to an allocator, a
// lock, a condition, a semaphore, file or socket I/O, a sleep or the server's Print is counted
// (audio_rules/Interpose.c, InterposeNew.cpp) with the UGen or command and the phase it happened
// in; the count must be 0.
//
// Usage: test_audio_thread_rules <plugin.so> --replay <hid-recorder file> --scratch <folder>
//                                [--expect-violation <function>:<UGen or command>]...
// --expect-violation: the plugin is a mutant (tests/host/CMakeLists.txt), and the run passes only
// if each named violation is reported: the test can fail.
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "audio_rules/Counting.h"
#include "audio_rules/FakeServer.hpp"
#include "audio_rules/UgenModes.hpp"

namespace {

using namespace kf::rules;
using Ms = std::chrono::milliseconds;

// A kf-drive file and its magnet table (docs/drive-format.md) in `folder`; the drive file's path.
std::string writeDriveFiles(const std::string& folder) {
  std::ofstream(folder + "/drive-magnet.txt") << "kf-calibration 1\n0 0.14\n1 1.4\n";
  std::ofstream(folder + "/drive.txt") << "kf-drive 1\nmagnetTable drive-magnet.txt\nfullScaleCurrentA 2\n"
                                          "transconductanceAPerV 0.5\noutputFullScaleV 10\noutputSign -1\n"
                                          "maxSafeCurrentA 2\ncurrentSourceLatencyS 0\nmagnetLagS 0\n";
  return folder + "/drive.txt";
}

struct Options {
  std::string plugin, replay, scratch;
  std::vector<std::string> expectedViolations;  // "function:UGen or command"
};

class Scenario {
 public:
  Scenario(FakeServer& server, const Options& options) : server_(server), options_(options) {}

  void run();
  const std::vector<std::string>& failures() const { return failures_; }

 private:
  void check(bool ok, const std::string& what) {
    if (!ok) failures_.push_back(what + " [phase: " + phase_ + "]");
  }
  void phase(const char* name) {
    phase_ = name;
    kf_rules_set_phase(name);
    std::printf("== %s\n", name);
  }
  // Runs `ms` of audio, the NRT side served meanwhile: the blocks of that much time at 48 kHz,
  // however long the wall clock takes. What the scenario needs is that the UGens ran that much
  // audio; an audio thread at normal priority (realtime refused) beside other load runs slower
  // than the clock (the UGens here need about 0.9 ms of CPU per 1.33 ms block, measured, so
  // beside two CPU hogs on two cores it got under 10 blocks in some 50 ms of wall time). The
  // limit only catches an audio thread that stopped.
  void runAudio(int ms) {
    const int64_t blocks =
        (ms * static_cast<int64_t>(FakeServer::kSampleRate) / FakeServer::kBlockSamples + 999) / 1000;
    const int64_t before = server_.blocks();
    const bool ran = server_.serveBlocks(blocks, kAudioLimit);
    check(ran, std::to_string(ms) + " ms of audio (" + std::to_string(blocks) + " blocks) ran within " +
                   std::to_string(kAudioLimit.count()) + " ms: only " + std::to_string(server_.blocks() - before));
  }
  static constexpr Ms kAudioLimit{10000};
  void expectDone(const OscMessage& message);
  void expectFailure(const OscMessage& message);
  void expectAnswer(const OscMessage& message);  // /done or /kfFail: what the machine has decides

  OscMessage openSim(bool replace) const {
    OscMessage message("kfOpenSim");
    message.i(0).i(1).i(4).f(80.f).f(5.f).f(-80.f).f(5.f);  // the hand: 80 mm/s for 5 s, then back
    // A firm hand, so that the puck moves whatever force the many writers of slot 0 add up to.
    message.s("handStiffnessNPerM").i(2000).s("handDampingNSPerM").i(20).s("handMaxForceN").i(20);
    if (replace) message.s("replace").i(1);
    return message;
  }

  FakeServer& server_;
  const Options& options_;
  std::string phase_;
  std::vector<std::string> failures_;
  kf::rules::ChainWatch chain_;
};

void Scenario::expectDone(const OscMessage& message) {
  const int dones = server_.doneCount(message.command());
  const int failures = server_.repliesNamed("/kfFail");
  server_.command(message);
  server_.serveUntil(
      [&] { return server_.doneCount(message.command()) > dones || server_.repliesNamed("/kfFail") > failures; },
      Ms(10000));
  check(server_.doneCount(message.command()) == dones + 1 && server_.repliesNamed("/kfFail") == failures,
        "/done (and no /kfFail) for " + message.describe());
}

void Scenario::expectFailure(const OscMessage& message) {
  const int dones = server_.doneCount(message.command());
  const int failures = server_.repliesNamed("/kfFail");
  server_.command(message);
  server_.serveUntil([&] { return server_.repliesNamed("/kfFail") > failures; }, Ms(10000));
  // A /kfFail comes from the command itself (refused: no stages follow), from its stage 3 (RT),
  // which sends stage 4 on in the same block, or from its stage 4 (NRT). So a /done could only
  // come from a stage 4 sent by the end of the block that sent the /kfFail: one round runs it.
  check(server_.settle(1, kAudioLimit), "the audio ran on after " + message.describe());
  check(server_.repliesNamed("/kfFail") == failures + 1 && server_.doneCount(message.command()) == dones,
        "/kfFail (and no /done) for " + message.describe());
}

void Scenario::expectAnswer(const OscMessage& message) {
  const int dones = server_.doneCount(message.command());
  const int failures = server_.repliesNamed("/kfFail");
  server_.command(message);
  check(server_.serveUntil(
            [&] { return server_.doneCount(message.command()) > dones || server_.repliesNamed("/kfFail") > failures; },
            Ms(10000)),
        "an answer to " + message.describe());
}

void Scenario::run() {
  for (const char* name : {"FrictionMouseIn", "FrictionButtons", "SpatialBufRd", "SpatialBufRd2D", "SpeedGovernor",
                           "LoudnessToFriction", "FrictionOut", "FrictionDrive", "FrictionPattern"})
    check(server_.unitDef(name).ctor != nullptr, std::string("the plugin defines ") + name);
  const std::string recording = options_.scratch + "/recording.txt";
  server_.start();
  if (server_.realtime())
    std::printf("the audio thread runs SCHED_FIFO %d, as JACK runs scsynth's\n", FakeServer::kAudioPriority);
  else
    std::printf("the audio thread runs at normal priority: realtime scheduling was refused\n");

  phase("1 no device open: every mode constructed and run");
  Synth* chain = server_.play(chainSynth(server_, chain_));
  Synth* mouseModes = server_.play(mouseModesSynth(server_));
  Synth* readers = server_.play(readersSynth(server_));
  Synth* surfaces = server_.play(surfacesSynth(server_));
  Synth* governors = server_.play(governorsSynth(server_));
  Synth* loudness = server_.play(loudnessSynth(server_));
  Synth* writers = server_.play(writersSynth(server_));
  Synth* drives = server_.play(drivesSynth(server_, chain_));
  Synth* patterns = server_.play(patternsSynth(server_));
  runAudio(200);

  phase("2 simulated device opened on slot 0 while the UGens run");
  expectDone(openSim(false));
  runAudio(400);
  check(chain_.largestXMm.load() > 1.f, "FrictionMouseIn followed the simulated puck");

  phase("3 recording on, then off");
  expectDone(OscMessage("kfRecord").i(0).s(recording));
  runAudio(200);
  expectDone(OscMessage("kfRecord").i(0).s(""));
  runAudio(100);

  phase("4 status and zero");
  const int statusReplies = server_.repliesNamed("/kfStatus");
  expectDone(OscMessage("kfStatus").i(0));
  server_.serveUntil([&] { return server_.repliesNamed("/kfStatus") > statusReplies; }, Ms(2000));
  expectDone(OscMessage("kfZero").i(0).f(10.f).f(0.f));
  runAudio(100);

  phase("5 replay device opened on slot 1");
  expectDone(OscMessage("kfOpenReplay").i(1).s(options_.replay).s("loop").i(1));
  Synth* slot1 = server_.play(slot1Synth(server_));
  runAudio(300);

  phase("6 an emulated board on slot 0");
  expectDone(OscMessage("kfBoardOpen").i(0).s("").i(1).i(2));
  expectDone(OscMessage("kfBoardCalibrate").i(0).s(""));
  expectDone(OscMessage("kfBoardStatus").i(0));
  runAudio(200);
  expectDone(OscMessage("kfBoardClose").i(0));

  phase("6b the audio drive loaded on slot 0, a bad file refused, removed");
  expectDone(OscMessage("kfDriveCalibrate").i(0).s(writeDriveFiles(options_.scratch)));
  runAudio(200);
  expectFailure(OscMessage("kfDriveCalibrate").i(0).s(options_.scratch + "/no-such-drive.txt"));
  expectFailure(OscMessage("kfDriveCalibrate").i(3).s(""));  // no device there: fails in stage 2 (NRT)
  runAudio(50);

  phase("7 slot 0 handed over to a new device while the UGens run");
  expectDone(openSim(true));
  runAudio(200);

  phase("8 refused and failing commands, and the mouse commands (no mouse needed)");
  expectFailure(openSim(false));                                      // slot taken: refused in stage 3
  expectFailure(OscMessage("kfRecord").i(2).s(recording + ".none"));  // no device: fails in stage 4 (NRT)
  expectFailure(OscMessage("kfClose").s("zero"));                     // bad argument: refused in the command
  expectFailure(OscMessage("kfZero").i(5));                           // no device: fails in the command
  expectFailure(OscMessage("kfReopenMouse").i(0));                    // the simulated device is no mouse
  expectFailure(OscMessage("kfOpenMouse").i(2).s("/nonexistent/hidraw9").s("hidapi").s(""));
  expectAnswer(OscMessage("kfListMice").s("").s(""));  // whatever mice this machine has
  runAudio(100);

  phase("9 units started and freed while the device is open");
  Synth* lateJoiners = server_.play(lateJoinersSynth(server_));
  runAudio(100);
  server_.free(writers);
  server_.free(lateJoiners);
  runAudio(100);

  phase("10 devices closed while the UGens run");
  expectDone(OscMessage("kfClose").i(0));
  runAudio(150);
  expectDone(OscMessage("kfClose").i(1));
  runAudio(100);

  phase("11 reopened, then freed with the device open and closed");
  expectDone(openSim(false));
  runAudio(150);
  server_.free(chain);
  server_.free(mouseModes);
  runAudio(50);
  expectDone(OscMessage("kfClose").i(0));
  server_.free(readers);
  server_.free(surfaces);
  server_.free(governors);
  server_.free(loudness);
  server_.free(patterns);
  server_.free(slot1);
  server_.free(drives);
  server_.serveUntil([&] { return server_.numSynths() == 0; }, Ms(5000));
  runAudio(50);
  server_.stop();

  // What must have happened for the run to mean anything.
  phase_ = "end";
  check(server_.numSynths() == 0, "every synth freed");
  check(chain_.largestForceN.load() > 0.f, "FrictionOut commanded a force");
  check(chain_.largestDrive.load() > 0.f, "FrictionDrive drove the slot's force");
  bool noDeviceWarned = false;
  for (const std::string& post : server_.posts())
    noDeviceWarned = noDeviceWarned || post.find("FrictionMouseIn: no device is open at index 0") != std::string::npos;
  check(noDeviceWarned, "the UGens' posts from the audio thread reached the NRT thread's Print");
  std::ifstream lines(recording);
  int numLines = 0;
  for (std::string line; std::getline(lines, line);) ++numLines;
  check(numLines > 20, "the recording has lines (" + std::to_string(numLines) + ")");
  const kf::rules::Reply* status = nullptr;
  for (const kf::rules::Reply& reply : server_.replies())
    if (reply.name == "/kfStatus") status = &reply;
  // The device thread really ran beside the audio thread: reports and frames went through the
  // queues, at a sane loop period and latency (how close to 1 ms is the bench's to measure).
  check(status != nullptr && status->values.size() >= 22, "/kfStatus replied");
  if (status != nullptr && status->values.size() >= 22) {
    const std::vector<float>& v = status->values;  // FrictionDevice.statusFields order
    std::printf(
        "/kfStatus: %g reports, %g frames, %g watchdog trips, %g missed deadlines, %g skipped; p50 loop period "
        "%.2f ms, force latency %.2f ms, report latency %.2f ms\n",
        v[6], v[7], v[8], v[9], v[10], v[14] * 1e3, v[17] * 1e3, v[21] * 1e3);
    check(v[0] == 1.f && v[1] == 1.f, "/kfStatus: open, realtime");
    check(v[6] > 20.f, "/kfStatus: reports delivered (" + std::to_string(v[6]) + ")");
    check(v[7] > 100.f, "/kfStatus: frames delivered (" + std::to_string(v[7]) + ")");
    check(v[14] > 0.f && v[14] < 0.02f, "/kfStatus: loop period p50 sane (" + std::to_string(v[14]) + " s)");
    check(v[17] < 0.02f, "/kfStatus: force latency p50 sane (" + std::to_string(v[17]) + " s)");
    check(v[21] > 0.f && v[21] < 0.02f,
          "/kfStatus: reports reached the UGens, latency p50 sane (" + std::to_string(v[21]) + " s)");
    // audioCallMaxS: FrictionOut's blocks were timed on the audio thread.
    check(v.size() > 29 && v[29] > 0.f && std::isfinite(v[29]),
          "/kfStatus: FrictionOut's longest block measured (" + std::to_string(v.size() > 29 ? v[29] : -1.f) + " s)");
  }
  check(server_.repliesNamed("/kfBoardStatus") == 1, "/kfBoardStatus replied");
  for (const std::string& problem : server_.problems())
    check(false, "the plugin used the interface wrongly: " + problem);
  // The interposers see the plugin's calls: its NRT stages allocate and lock, as they may.
  const uint64_t allocations = kf_rules_witnessed(kf_call_operator_new) + kf_rules_witnessed(kf_call_malloc);
  check(allocations > 0, "the interposers saw the plugin's NRT allocations");
  check(kf_rules_witnessed(kf_call_pthread_mutex_lock) > 0, "the interposers saw the plugin's NRT locks");
}

Options parse(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool hasValue = i + 1 < argc;
    if (arg == "--replay" && hasValue)
      options.replay = argv[++i];
    else if (arg == "--scratch" && hasValue)
      options.scratch = argv[++i];
    else if (arg == "--expect-violation" && hasValue)
      options.expectedViolations.push_back(argv[++i]);
    else if (options.plugin.empty() && arg.rfind("--", 0) != 0)
      options.plugin = arg;
    else
      throw std::runtime_error("unknown argument " + arg);
  }
  if (options.plugin.empty() || options.replay.empty() || options.scratch.empty())
    throw std::runtime_error(
        "usage: test_audio_thread_rules <plugin.so> --replay <hid file> --scratch <folder> "
        "[--expect-violation function:UGen]...");
  return options;
}

// Whether a violation of `function` in a unit or command whose label contains `where` was seen.
bool seen(const std::vector<KfRulesViolation>& violations, const std::string& expected) {
  const size_t colon = expected.find(':');
  const std::string function = expected.substr(0, colon);
  const std::string where = colon == std::string::npos ? "" : expected.substr(colon + 1);
  for (const KfRulesViolation& v : violations)
    if (function == kf_rules_name(v.call) && std::strstr(v.detail, where.c_str()) != nullptr) return true;
  return false;
}

// What was counted: each function's total with where it first happened, then every kind
// (function, activity, UGen or command, phase), the first 40; the scenario's failed checks; what
// was interposed, and what was witnessed on the NRT thread.
void report(const std::vector<KfRulesViolation>& violations, const std::vector<std::string>& failures) {
  auto where = [](const KfRulesViolation& v) {
    return std::string("the ") + v.activity + " of " + v.detail + " [phase " + v.phase + "]";
  };
  for (int i = 0; i < kf_num_calls; ++i) {
    const auto call = static_cast<KfRulesCall>(i);
    const uint64_t count = kf_rules_count(call);
    if (count == 0) continue;
    std::string first;
    for (const KfRulesViolation& v : violations)
      if (v.call == call && first.empty()) first = ", first in " + where(v);
    std::printf("COUNTED: %s called %llu times on the audio thread%s\n", kf_rules_name(call),
                static_cast<unsigned long long>(count), first.c_str());
  }
  const size_t shown = std::min<size_t>(violations.size(), 40);
  for (size_t i = 0; i < shown; ++i)
    std::printf("VIOLATION: %s x%llu in %s\n", kf_rules_name(violations[i].call),
                static_cast<unsigned long long>(violations[i].count), where(violations[i]).c_str());
  if (violations.size() > shown) std::printf("... and %zu more kinds of violation\n", violations.size() - shown);
  for (const std::string& failure : failures) std::printf("FAILED: %s\n", failure.c_str());
  std::printf("interposed on the audio thread:");
  for (int i = 0; i < kf_num_calls; ++i) std::printf(" %s", kf_rules_name(static_cast<KfRulesCall>(i)));
  const uint64_t allocations = kf_rules_witnessed(kf_call_operator_new) + kf_rules_witnessed(kf_call_malloc);
  std::printf("\nwitnessed on the NRT thread (the plugin's stages 2 and 4): %llu allocations, %llu mutex locks\n",
              static_cast<unsigned long long>(allocations),
              static_cast<unsigned long long>(kf_rules_witnessed(kf_call_pthread_mutex_lock)));
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    mkdir(options.scratch.c_str(), 0755);
    std::vector<std::string> failures;
    {
      FakeServer server(options.plugin);
      Scenario scenario(server, options);
      scenario.run();
      failures = scenario.failures();
    }
    std::vector<KfRulesViolation> violations(256);
    violations.resize(static_cast<size_t>(std::min(256, kf_rules_violations(violations.data(), 256))));
    report(violations, failures);
    if (options.expectedViolations.empty()) {
      std::printf(violations.empty() && failures.empty() ? "PASSED: nothing counted on the audio thread\n"
                                                         : "FAILED\n");
      return violations.empty() && failures.empty() ? 0 : 1;
    }
    bool allSeen = true;
    for (const std::string& expected : options.expectedViolations) {
      const bool found = seen(violations, expected);
      allSeen = allSeen && found;
      std::printf("%s: the mutant's %s\n", found ? "caught" : "MISSED", expected.c_str());
    }
    std::printf(allSeen && failures.empty() ? "PASSED: the mutant's violations were reported\n" : "FAILED\n");
    return allSeen && failures.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "test_audio_thread_rules: %s\n", e.what());
    return 2;
  }
}
