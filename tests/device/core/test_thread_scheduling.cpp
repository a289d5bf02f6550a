// The device's threads as realtime citizens: named, SCHED_FIFO at a priority relative to the
// audio thread where the system grants it, and where it does not (a user without an rtprio
// limit), at normal priority with one message naming the fix, and a device that works.
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "../WaitFor.hpp"
#include "DeviceFactory.hpp"
#include "core/threads/DeviceMessages.hpp"
#include "core/threads/ThreadScheduling.hpp"

using namespace kf;

namespace {

// Runs `body` on a thread of its own (scheduling changes stay there) and returns its result.
template <class Body>
auto onThread(Body body) {
  decltype(body()) result{};
  std::thread([&] { result = body(); }).join();
  return result;
}

std::string threadName() {
  char name[32] = {};
  pthread_getname_np(pthread_self(), name, sizeof(name));
  return name;
}

// Whether this process may use SCHED_FIFO at all (root, CAP_SYS_NICE, an rtprio limit).
bool fifoAllowed() {
  return onThread([] {
    sched_param param{};
    param.sched_priority = 1;
    return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  });
}

// The names of this process's threads, from /proc.
std::string threadNames() {
  std::string names;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream comm(task.path() / "comm");
    std::string name;
    if (std::getline(comm, name)) names += name + "\n";
  }
  return names;
}

std::string gMessages;
int gMessageCount = 0;
void collect(const char* message) {
  gMessages += message;
  ++gMessageCount;
}

}  // namespace

TEST_CASE("the priority of our threads: one above a realtime audio thread, else the fallback", "[scheduling]") {
  noteAudioThreadPriority(-1);  // unknown (a Score render, the unit tests)
  CHECK(resolvePriority(kAutoPriority) == kFallbackPriority);
  noteAudioThreadPriority(0);  // the audio thread is not realtime (jackd -r)
  CHECK(resolvePriority(kAutoPriority) == kFallbackPriority);
  noteAudioThreadPriority(65);  // jackd -R -P 70: its clients' process threads at 65
  CHECK(resolvePriority(kAutoPriority) == 66);
  noteAudioThreadPriority(98);
  CHECK(resolvePriority(kAutoPriority) == kMaxPriority);
  noteAudioThreadPriority(-1);
  CHECK(resolvePriority(kNormalPriority) == 0);
  CHECK(resolvePriority(40) == 40);
  CHECK(resolvePriority(200) == kMaxPriority);
  CHECK(resolvePriority(-7) == 0);
}

TEST_CASE("a thread is named after its role and slot and gets what it asks where allowed", "[scheduling]") {
  struct Got {
    ThreadScheduling scheduling;
    std::string name;
    int priority = -1;
  };
  const Got normal = onThread([] {
    const ThreadScheduling s = scheduleThisThread("mouse", {7, kNormalPriority});
    return Got{s, threadName(), currentThreadPriority()};
  });
  CHECK(normal.name == "kf-mouse-7");
  CHECK(normal.scheduling.priority == 0);
  CHECK(normal.priority == 0);
  CHECK(describe(normal.scheduling).rfind("normal priority", 0) == 0);

  const Got fifo = onThread([] {
    const ThreadScheduling s = scheduleThisThread("device", {12, 20});
    return Got{s, threadName(), currentThreadPriority()};
  });
  CHECK(fifo.name == "kf-device-12");
  if (fifoAllowed()) {
    CHECK(fifo.scheduling.priority == 20);
    CHECK(fifo.priority == 20);
    CHECK(describe(fifo.scheduling).rfind("SCHED_FIFO 20", 0) == 0);
  } else {
    CHECK(fifo.scheduling.priority == 0);
  }
  CHECK(describe(ThreadScheduling{}) == "not started");
}

TEST_CASE("asked for normal priority, a thread leaves a realtime policy it inherited", "[scheduling]") {
  if (!fifoAllowed()) return;  // nothing to inherit without realtime rights
  const int priority = onThread([] {
    sched_param param{};
    param.sched_priority = 30;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);  // a realtime creator (scsynth's)
    return onThread([] { return scheduleThisThread("device", {0, kNormalPriority}).priority; });
  });
  CHECK(priority == 0);
}

TEST_CASE("the device thread carries its name and its scheduling is reported", "[scheduling]") {
  DeviceOptions options;
  options.thread = {5, 30};
  std::string error;
  auto device = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::speeds({{20.0, 1.0}}), false, &error, options);
  REQUIRE(device);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const TelemetrySnapshot t = device->telemetry();
  CHECK(t.pumps > 10);
  CHECK(t.deviceThread.priority == (fifoAllowed() ? 30 : 0));
  CHECK(t.mouseThread.priority == -1);  // the simulator reads no mouse
  CHECK(threadNames().find("kf-device-5\n") != std::string::npos);
}

TEST_CASE("refused realtime: normal priority, one message with the fix, and a working device", "[scheduling]") {
  // In a child that may not use realtime scheduling: no rtprio limit, and not root (root ignores
  // the limit) — as a user who has not joined the audio group.
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    const rlimit none{0, 0};
    if (setrlimit(RLIMIT_RTPRIO, &none) != 0) _exit(10);
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(11);
    setDeviceMessageSink(collect);
    DeviceOptions options;
    options.thread = {2, 40};
    std::string error;
    auto first = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::speeds({{20.0, 1.0}}), false, &error, options);
    auto second = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::speeds({{20.0, 1.0}}), false, &error, options);
    if (!first || !second) _exit(12);
    // Working: pumping, the puck reporting. At normal priority the pace is the machine's: after a
    // fixed 60 ms a fresh clone's run beside the other busy tests saw too few (exit 14), so it
    // waits for them, 3 s at most (a device that never pumps or reports still fails).
    TelemetrySnapshot t;
    test::waitFor([&] {
      t = first->telemetry();
      return t.pumps >= 20 && t.reports >= 3;
    });
    if (t.deviceThread.priority != 0) _exit(13);  // normal priority
    if (t.pumps < 20 || t.reports < 3) _exit(14);
    if (gMessageCount != 1) _exit(15);  // one message for both devices
    if (gMessages.find("kf-device-2") == std::string::npos || gMessages.find("rtprio") == std::string::npos ||
        gMessages.find("limits.d") == std::string::npos || gMessages.find("memlock") == std::string::npos)
      _exit(16);
    _exit(0);
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);  // 13: not normal; 14: not working; 15/16: the message
}
