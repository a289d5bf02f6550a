// The device thread's CPU at each force rate: a realtime Device (its 1 ms pump thread) with a
// board on the emulated bus (UsbBoardBackend and its USB event thread, as kfBoardOpen makes them),
// fed force frames at the rate as FrictionOut feeds them (a 100 Hz grating, each frame pushed when
// its period has passed), for `seconds` per run: at 1 kHz (protocol 2.0's one set-point per 1 ms
// frame) and at 8 kHz (2.1: eight per frame). Counted: the host's threads, the ones named kf-...,
// the time each ran on a CPU over the run (/proc/self/task/<tid>/schedstat); not the emulated
// board's thread (the board's side of the bus) nor this feeding thread (the audio side). The two
// rates alternate in each round (which goes first alternates too). Prints one JSON object.
#include <dirent.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "board/EmulatedUsb.hpp"
#include "board/UsbBoardBackend.hpp"
#include "core/Device.hpp"
#include "recordings/ReplayBackend.hpp"

namespace {

// CPU seconds of this process's threads whose name starts with "kf-": the time each ran on a CPU,
// in ns, from /proc/self/task/<tid>/schedstat (its first field).
double hostThreadsCpuS() {
  double total = 0;
  DIR* dir = opendir("/proc/self/task");
  if (dir == nullptr) return 0;
  while (const dirent* entry = readdir(dir)) {
    if (entry->d_name[0] == '.') continue;
    const std::string task = std::string("/proc/self/task/") + entry->d_name;
    std::string name;
    std::getline(std::ifstream(task + "/comm"), name);
    if (name.rfind("kf-", 0) != 0) continue;
    double ranNs = 0;
    std::ifstream(task + "/schedstat") >> ranNs;
    total += ranNs * 1e-9;
  }
  closedir(dir);
  return total;
}

struct Run {
  double cpuS, setPointsPerS;
};

Run runAt(int perFrame, double seconds) {
  auto bus = kf::board::EmulatedUsb::create();
  kf::BoardOptions boardOptions;
  boardOptions.subSetPoints = perFrame;
  auto board = std::make_shared<kf::UsbBoardBackend>(bus->makePort(), boardOptions);
  std::string error;
  if (!board->open(error)) {
    std::fprintf(stderr, "device_rate_bench: %s\n", error.c_str());
    std::exit(1);
  }
  kf::DeviceSpec spec;
  spec.forceFramePeriodS = kf::board::kFramePeriodS / perFrame;
  auto device = std::make_unique<kf::Device>(spec, std::make_shared<kf::ReplayBackend>(std::vector<kf::TimedReport>{}),
                                             std::make_shared<kf::CountingForceSink>(), false);
  device->start();
  if (device->attachBoard(board) != nullptr || !board->arm(error)) {
    std::fprintf(stderr, "device_rate_bench: the board did not arm: %s\n", error.c_str());
    std::exit(1);
  }
  const double periodS = spec.forceFramePeriodS;
  const double startS = device->nowS();
  const double cpu0 = hostThreadsCpuS();
  const uint16_t sequence0 = board->telemetry().lastSequenceSent;
  const auto frames = static_cast<long>(seconds / periodS);
  for (long i = 0; i < frames; ++i) {
    const double frameS = startS + i * periodS;
    // Each frame pushed once its period has passed (checked every 200 us: at 8 kHz one or two at once).
    while (device->nowS() < frameS + periodS) std::this_thread::sleep_for(std::chrono::microseconds(200));
    const float forceN = static_cast<float>(0.77 + 0.63 * std::sin(2 * M_PI * 100 * i * periodS));
    device->pushForceFrame({frameS, forceN, frameS + periodS});
  }
  const double cpuS = hostThreadsCpuS() - cpu0;
  const auto sent = static_cast<uint16_t>(board->telemetry().lastSequenceSent - sequence0);
  device->close();
  return {cpuS / seconds, board->telemetry().subSetPoints * sent / seconds};
}

}  // namespace

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::atoi(argv[1]) : 3;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 2.0;
  const int rates[] = {1, 8};
  std::vector<Run> runs[2];
  for (int round = 0; round < rounds; ++round)
    for (int k = 0; k < 2; ++k) {
      const int r = (round + k) % 2;
      runs[r].push_back(runAt(rates[r], seconds));
    }
  std::printf("{\"seconds\": %g, \"rounds\": %d, \"rates\": [", seconds, rounds);
  for (int r = 0; r < 2; ++r) {
    std::printf("{\"rateHz\": %d, \"cpuSPerS\": [", 1000 * rates[r]);
    for (size_t i = 0; i < runs[r].size(); ++i)
      std::printf("%.6f%s", runs[r][i].cpuS, i + 1 < runs[r].size() ? ", " : "], \"setPointsPerS\": [");
    for (size_t i = 0; i < runs[r].size(); ++i)
      std::printf("%.1f%s", runs[r][i].setPointsPerS, i + 1 < runs[r].size() ? ", " : "]}");
    std::printf(r == 0 ? ", " : "]}\n");
  }
  return 0;
}
