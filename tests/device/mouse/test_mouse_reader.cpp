// The reader thread against what real kernels and libraries do to it: signals that interrupt a
// blocking poll (hidapi then returns -1, as for an unplug), evdev's SYN_DROPPED taking a button
// change with it, and hidapi's global state used from several threads at once.
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <unistd.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <csignal>
#include <thread>

#include "mouse/EvdevMouseBackend.hpp"
#include "mouse/HidapiMouseBackend.hpp"
#include "recordings/HidRecorderFile.hpp"

using namespace kf;

namespace {

// --- a hidapi handle over a real pipe: poll() as hid_read_timeout does, -1 on any error ---

struct PipeMouse {
  int fds[2] = {-1, -1};
  std::atomic<pthread_t> readerThread{};
  std::atomic<bool> readerSeen{false};
  sigset_t readerMask{};
  PipeMouse() { REQUIRE(::pipe2(fds, O_CLOEXEC) == 0); }
  ~PipeMouse() {
    ::close(fds[0]);
    ::close(fds[1]);
  }
};

class PipeHidHandle : public HidHandle {
 public:
  explicit PipeHidHandle(PipeMouse& mouse) : mouse_(mouse) {}
  // hidapi 0.13's hid_read_timeout on Linux: poll, then read; poll's -1 (EINTR included) is -1.
  int readTimeout(uint8_t* buffer, size_t capacity, int timeoutMs) override {
    if (!mouse_.readerSeen.load()) {
      pthread_sigmask(SIG_BLOCK, nullptr, &mouse_.readerMask);
      mouse_.readerThread.store(pthread_self());
      mouse_.readerSeen.store(true);
    }
    pollfd wait{mouse_.fds[0], POLLIN, 0};
    const int ready = ::poll(&wait, 1, timeoutMs);
    if (ready <= 0) return ready;
    return static_cast<int>(::read(mouse_.fds[0], buffer, capacity));
  }
  std::string lastError() override { return "hid_read_timeout: error polling the device"; }
  bool reportDescriptor(std::vector<uint8_t>& out, std::string& error) override {
    HidRecording genius;
    if (!readHidRecorderFile(KF_HID_RECORDING, genius, error)) return false;
    out = genius.descriptor;
    return true;
  }

 private:
  PipeMouse& mouse_;
};

class PipeHidApi : public HidApi {
 public:
  explicit PipeHidApi(PipeMouse& mouse) : mouse_(mouse) {}
  bool enumerateMice(std::vector<MouseInfo>& out, std::string&) override {
    MouseInfo info;
    info.path = "/dev/hidraw3";
    out = {info};
    return true;
  }
  std::unique_ptr<HidHandle> openPath(const std::string&, std::string&, OpenFailure& why) override {
    why = OpenFailure::kNone;
    return std::make_unique<PipeHidHandle>(mouse_);
  }

 private:
  PipeMouse& mouse_;
};

std::atomic<int> handledSignals{0};
void countSignal(int) { handledSignals.fetch_add(1); }

// --- an evdev handle that hands out a fixed list of events once --------------------------

class ScriptedEvdevHandle : public EvdevHandle {
 public:
  ScriptedEvdevHandle(std::vector<EvdevEvent> events, uint32_t buttonsNow)
      : events_(std::move(events)), buttonsNow_(buttonsNow) {}
  bool setMonotonicClock(std::string&) override { return true; }
  bool grab(bool, std::string&) override { return true; }
  std::string name() override { return "scripted mouse"; }
  bool id(uint16_t& vendorId, uint16_t& productId) override {
    vendorId = 0x046d, productId = 0x4082;
    return true;
  }
  bool buttonsDown(uint32_t& buttons) override {
    buttons = buttonsNow_;
    return true;
  }
  int read(EvdevEvent* out, int capacity, int timeoutMs, int*) override {
    if (given_ || capacity < static_cast<int>(events_.size())) {
      std::this_thread::sleep_for(std::chrono::milliseconds(timeoutMs));
      return 0;
    }
    std::copy(events_.begin(), events_.end(), out);
    given_ = true;
    return static_cast<int>(events_.size());
  }

 private:
  std::vector<EvdevEvent> events_;
  uint32_t buttonsNow_;
  bool given_ = false;
};

class ScriptedEvdevApi : public EvdevApi {
 public:
  ScriptedEvdevApi(std::vector<EvdevEvent> events, uint32_t buttonsNow)
      : events_(std::move(events)), buttonsNow_(buttonsNow) {}
  bool enumerateMice(std::vector<MouseInfo>& out, std::string&) override {
    MouseInfo info;
    info.path = "/dev/input/event4";
    out = {info};
    return true;
  }
  std::unique_ptr<EvdevHandle> open(const std::string&, std::string&, OpenFailure& why) override {
    why = OpenFailure::kNone;
    return std::make_unique<ScriptedEvdevHandle>(events_, buttonsNow_);
  }

 private:
  std::vector<EvdevEvent> events_;
  uint32_t buttonsNow_;
};

}  // namespace

TEST_CASE("a signal sent to the reader thread does not read as an unplug: it never reaches it", "[mouse][signal]") {
  // A handler without SA_RESTART, as a host program (or a profiler) may install: a thread that
  // takes the signal sees poll() fail with EINTR.
  struct sigaction counting = {}, previous = {};
  counting.sa_handler = countSignal;
  sigemptyset(&counting.sa_mask);
  REQUIRE(sigaction(SIGUSR1, &counting, &previous) == 0);
  handledSignals = 0;

  PipeMouse pipe;
  std::string error;
  auto backend = HidapiMouseBackend::open(std::make_shared<PipeHidApi>(pipe), "", error);
  REQUIRE(backend);
  for (int i = 0; i < 1000 && !pipe.readerSeen.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  REQUIRE(pipe.readerSeen.load());

  // Its mask: every asynchronous signal blocked, the faults it may cause itself not (the exit
  // handlers that switch the magnet off must still run on a crash).
  for (int blocked : {SIGINT, SIGTERM, SIGHUP, SIGUSR1, SIGUSR2, SIGALRM, SIGCHLD, SIGPROF, SIGPIPE}) {
    INFO("signal " << blocked);
    CHECK(sigismember(&pipe.readerMask, blocked) == 1);
  }
  for (int fault : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) {
    INFO("signal " << fault);
    CHECK(sigismember(&pipe.readerMask, fault) == 0);
  }

  // Signals aimed at the reader thread itself, while it waits in poll.
  for (int i = 0; i < 5; ++i) {
    REQUIRE(pthread_kill(pipe.readerThread.load(), SIGUSR1) == 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(3 * RealMouseBackend::kReadTimeoutMs));
  CHECK(handledSignals.load() == 0);
  CHECK(backend->state() == MouseState::kRunning);
  CHECK(backend->counters().unplugs == 0);

  // And it still reads: the Genius mouse's report 1 (ID, buttons, int16 X, int16 Y, wheel, pan).
  const uint8_t report[8] = {1, 0, 5, 0, 0xfd, 0xff, 0, 0};
  REQUIRE(::write(pipe.fds[1], report, sizeof report) == static_cast<ssize_t>(sizeof report));
  MouseReport got;
  int n = 0;
  for (int i = 0; i < 1000 && n == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    n = backend->pollReports(0.0, &got, 1);
  }
  REQUIRE(n == 1);
  CHECK(got.dxCounts == 5);
  CHECK(got.dyCounts == -3);
  backend->stop();  // a signal still pending on the reader goes with the thread
  sigaction(SIGUSR1, &previous, nullptr);
}

TEST_CASE("evdev: after SYN_DROPPED the buttons are read back, a release lost in the drop is not kept",
          "[mouse][evdev]") {
  constexpr uint16_t kSyn = 0, kKey = 1, kRel = 2, kReport = 0, kDropped = 3, kBtnLeft = 0x110;
  // The left button goes down; the queue overflows and its release is among what was thrown
  // away; the kernel's state (EVIOCGKEY) says nothing is down.
  const std::vector<EvdevEvent> events = {{1.000, kKey, kBtnLeft, 1}, {1.000, kRel, 0, 2},
                                          {1.000, kSyn, kReport, 0},                              // pressed
                                          {1.010, kSyn, kDropped, 0},                             // overflow
                                          {1.012, kRel, 0, 4},        {1.012, kSyn, kReport, 0},  // the broken packet
                                          {1.020, kRel, 0, 3},        {1.020, kSyn, kReport, 0}};
  std::string error;
  auto backend = EvdevMouseBackend::open(std::make_shared<ScriptedEvdevApi>(events, 0u), "", false, error);
  REQUIRE(backend);
  std::vector<MouseReport> reports;
  MouseReport buffer[8];
  for (int i = 0; i < 1000 && reports.size() < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const int n = backend->pollReports(0.0, buffer, 8);
    reports.insert(reports.end(), buffer, buffer + n);
  }
  REQUIRE(reports.size() == 3);
  CHECK(reports[0].buttons == 1);
  CHECK(reports[0].dxCounts == 2);
  // At the end of the drop: the release, at once, flagged after the loss.
  CHECK(reports[1].buttons == 0);
  CHECK(reports[1].dxCounts == 0);
  CHECK(reports[1].flags & kAfterLoss);
  CHECK(reports[2].buttons == 0);
  CHECK(reports[2].dxCounts == 3);
  CHECK(backend->counters().lossEvents == 1);
}

TEST_CASE("hidapi's global state is used by one thread at a time: opens and enumerations from four",
          "[mouse][hid][real]") {
  // A failing hid_open_path replaces (frees) hidapi's one global error string, and
  // hid_enumerate clears it; we read it after. Four threads doing both at once, as a re-open
  // and a command may, free and read it under each other without the lock in HidapiIo.
  const std::shared_ptr<HidApi> api = realHidApi();
  std::atomic<int> wrongAnswers{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 200; ++i) {
        std::string error;
        OpenFailure why = OpenFailure::kNone;
        const std::string path = "/dev/hidraw-kf-none-" + std::to_string(t);
        if (api->openPath(path, error, why) != nullptr || error.find(path) == std::string::npos)
          wrongAnswers.fetch_add(1);
        std::vector<MouseInfo> mice;
        if (i % 20 == 0 && !api->enumerateMice(mice, error)) wrongAnswers.fetch_add(1);
      }
    });
  for (std::thread& thread : threads) thread.join();
  CHECK(wrongAnswers.load() == 0);
}
