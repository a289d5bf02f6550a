// The plugin's ways out: when scsynth exits (/quit: the exit hook in host/DeviceSlots.cpp)
// or is ended by a signal (host/ExitSafety.cpp), every device still in a slot, and every
// device taken out of its slot whose close has not run yet (a kfClose followed at once by /quit
// or a signal), has its magnet driven off. Run in a child process, whose exit runs the hook;
// the magnet's drive-offs are written to a pipe.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <utility>

#include "DeviceSlots.hpp"
#include "ExitSafety.hpp"
#include "SlotDrive.hpp"
#include "recordings/ReplayBackend.hpp"

namespace {

class PipeSink : public kf::ForceBackend {
 public:
  PipeSink(int fd, char name) : fd_(fd), name_(name) {}
  void commandForce(double, float) override {}
  void driveOff() override { (void)!write(fd_, &name_, 1); }

 private:
  int fd_;
  char name_;
};

kf::Device* newDevice(int fd, char name) {
  auto device = new kf::Device(kf::DeviceSpec{}, std::make_shared<kf::ReplayBackend>(std::vector<kf::TimedReport>{}),
                               std::make_shared<PipeSink>(fd, name), false);
  device->start();
  return device;
}

// Runs `child` in a forked process that writes drive-offs to a pipe; returns what it wrote and
// the child's wait status.
template <typename Child>
std::pair<std::string, int> offsWrittenBy(Child child) {
  int fds[2];
  REQUIRE(pipe(fds) == 0);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    close(fds[0]);
    child(fds[1]);
    std::_Exit(99);  // not reached: the child ends by exit or by its signal
  }
  close(fds[1]);
  std::string offs;
  char buffer[16];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) offs.append(buffer, static_cast<size_t>(n));
  close(fds[0]);
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  return {offs, status};
}

}  // namespace

TEST_CASE("server exit closes open devices and those whose close has not finished", "[safety]") {
  const std::string recording = "kf-exit-hook-" + std::to_string(getpid()) + ".txt";
  const auto [offs, status] = offsWrittenBy([&recording](int fd) {
    kf::Device* recorded = newDevice(fd, 'a');
    std::string error;
    if (!recorded->startRecording(recording, error)) std::_Exit(98);
    kf::sc::exchangeSlot(5, recorded);  // open at exit, recording: the hook closes the file too
    kf::sc::exchangeSlot(6, newDevice(fd, 'b'));
    kf::sc::exchangeSlot(6, nullptr);  // kfClose's RT stage ran, its NRT stage (delete) did not
    kf::sc::exchangeSlot(7, newDevice(fd, 'c'));
    kf::sc::deleteRetired(kf::sc::exchangeSlot(7, nullptr));  // a close that finished: 'c' now
    std::exit(0);                                             // static destructors: the exit hook
  });
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  // Each magnet went off exactly once: 'c' at its close, 'a' and 'b' by the exit hook.
  CHECK(offs.size() == 3);
  CHECK(offs.find('a') != std::string::npos);
  CHECK(offs.find('b') != std::string::npos);
  CHECK(offs.find('c') == 0);
  // The recording was closed by the hook after the file registry's own statics could be gone
  // (a use after free there, found by AddressSanitizer in scsynth): it ends with the off record.
  std::ifstream file(recording);
  std::string line, last;
  while (std::getline(file, line))
    if (!line.empty()) last = line;
  CHECK(last.rfind("O ", 0) == 0);
  std::remove(recording.c_str());
}

TEST_CASE("a signal drives off open devices and those whose close has not finished", "[safety]") {
  // Every signal whose default action ends the process (signal(7)), but SIGXFSZ (the next test).
  const std::initializer_list<int> all{SIGTERM, SIGINT,    SIGHUP,  SIGQUIT, SIGUSR1, SIGUSR2, SIGPIPE,
                                       SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU, SIGPWR,  SIGABRT, SIGSYS,
                                       SIGTRAP, SIGSTKFLT, SIGSEGV, SIGBUS,  SIGFPE,  SIGILL};
  for (const int signalNumber : all) {
#if defined(__SANITIZE_ADDRESS__)
    // AddressSanitizer's own handlers of these, which ours hands the signal on to, report and abort.
    if (signalNumber == SIGSEGV || signalNumber == SIGBUS || signalNumber == SIGFPE || signalNumber == SIGILL) continue;
#endif
    CAPTURE(signalNumber);
    const auto [offs, status] = offsWrittenBy([signalNumber, &all](int fd) {
      // No core file from the crash signals (their default action dumps core).
      const rlimit noCore{0, 0};
      setrlimit(RLIMIT_CORE, &noCore);
      // As in scsynth: nothing handles these before the plugin (Catch2 installs handlers of its
      // own, which ours would hand the signal on to).
      for (const int other : all) signal(other, SIG_DFL);
      installExitSafety();
      kf::sc::exchangeSlot(5, newDevice(fd, 'a'));  // open
      kf::sc::exchangeSlot(6, newDevice(fd, 'b'));
      kf::sc::exchangeSlot(6, nullptr);  // closing: out of its slot, not deleted yet
      raise(signalNumber);
    });
    // The handler passed the signal on: the process ended by it, as without the handler...
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == signalNumber);
    // ... after driving both magnets off, once each.
    CHECK(offs.size() == 2);
    CHECK(offs.find('a') != std::string::npos);
    CHECK(offs.find('b') != std::string::npos);
  }
}

TEST_CASE("a file size limit does not end the process: SIGXFSZ is ignored, the write fails", "[safety]") {
  const auto [offs, status] = offsWrittenBy([](int fd) {
    signal(SIGXFSZ, SIG_DFL);
    installExitSafety();
    kf::sc::exchangeSlot(7, newDevice(fd, 'c'));
    raise(SIGXFSZ);  // as the kernel sends it to a write past RLIMIT_FSIZE
    _exit(42);       // still here, nothing driven off: the magnet goes on as commanded
  });
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 42);
  CHECK(offs.empty());
}

TEST_CASE("a signal zeroes every audio drive, also when the host's handler keeps the process alive", "[safety]") {
  const auto [written, status] = offsWrittenBy([](int fd) {
    // The host handles SIGUSR1 and lives on: our handler runs first, then hands it on.
    signal(SIGUSR1, [](int) {});
    installExitSafety();
    kf::sc::SlotForce force;
    force.reset(kf::DeviceSpec{});
    force.registerWriter();
    kf::DriveCircuit circuit;
    circuit.fullScaleCurrentA = circuit.maxSafeCurrentA = 2.0;
    circuit.transconductanceAPerV = 0.5;
    circuit.outputFullScaleV = 10.0;
    circuit.magnet = kf::CalibrationTable::linear(0.14, 1.4);
    kf::sc::SlotDrive* drive = kf::sc::driveOfSlot(2);
    drive->publish(new kf::AudioDrive(kf::DeviceSpec{}, circuit, 48000.0), 1);
    auto sink = [](double, float forceN, double) { return forceN; };
    const float forceN[1] = {1.0f};
    auto clock = [](int64_t block) { return kf::sc::BlockClock{block, block * 64 / 48000.0, 1.0 / 48000.0, 64}; };
    force.write(clock(0), forceN, 1, sink);
    force.write(clock(1), forceN, 1, sink);
    bool another = false;
    const float* before = drive->samples(clock(1), 1, force, another);
    (void)!write(fd, before != nullptr && before[63] > 0.0f ? "d" : "-", 1);  // driving before
    raise(SIGUSR1);
    force.write(clock(2), forceN, 1, sink);
    (void)!write(fd, drive->samples(clock(2), 1, force, another) == nullptr ? "0" : "-", 1);  // nothing after
    std::_Exit(0);
  });
  CHECK(WIFEXITED(status));
  CHECK(written == "d0");
}
