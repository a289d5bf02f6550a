// Issue 13, items 3 and 4 (device side): recordings never fail silently — write errors stop
// the recording cleanly with what was written kept, and are posted; special files and a
// second writer of one file are refused. The magnet goes off when the device thread dies of
// an exception, and from a signal handler (emergencyOff) with an off record appended.
#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "DeviceFactory.hpp"
#include "core/Device.hpp"
#include "core/files/RecordingWriter.hpp"
#include "core/files/SessionFile.hpp"
#include "core/threads/DeviceMessages.hpp"
#include "sim/SimDevice.hpp"

using namespace kf;

namespace {

std::string outputPath(const std::string& name) { return std::string(KF_TEST_OUTPUT_DIR) + "/recsafety-" + name; }

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::mutex gMessagesMutex;
std::vector<std::string> gMessages;
void collectMessage(const char* message) {
  std::lock_guard<std::mutex> lock(gMessagesMutex);
  gMessages.emplace_back(message);
}
std::vector<std::string> takeMessages() {
  std::lock_guard<std::mutex> lock(gMessagesMutex);
  return std::move(gMessages);
}

// A recording stopped by a write error: posted once, and its file holds whole lines within the
// size limit.
void checkStoppedByWriteError(const std::string& path, size_t limitBytes) {
  const std::vector<std::string> messages = takeMessages();
  REQUIRE(messages.size() == 1);
  CHECK(contains(messages[0], "kfRecord: writing "));
  setDeviceMessageSink(nullptr);
  const std::string text = readAll(path);
  CHECK(text.size() <= limitBytes);
  REQUIRE(!text.empty());
  CHECK(text.back() == '\n');
}

// Limits the size of files this process writes (EFBIG past it), for the scope.
struct FileSizeLimit {
  explicit FileSizeLimit(rlim_t bytes) {
    ::signal(SIGXFSZ, SIG_IGN);  // write() fails with EFBIG instead of killing the process
    ::getrlimit(RLIMIT_FSIZE, &saved);
    rlimit limit = saved;
    limit.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() { ::setrlimit(RLIMIT_FSIZE, &saved); }
  rlimit saved{};
};

class CountingForce : public ForceBackend {
 public:
  void commandForce(double, float forceN) override { lastN = forceN; }
  void driveOff() override { ++offs; }
  void driveOffFromSignal() noexcept override { ++signalOffs; }
  std::atomic<float> lastN{0.0f};
  std::atomic<int> offs{0};
  std::atomic<int> signalOffs{0};
};

// Throws from the device thread after a few polls, as a failing driver would.
class ThrowingMouse : public MouseBackend {
 public:
  int pollReports(double, MouseReport*, int) override {
    if (++polls > 5) throw std::runtime_error("driver lost the device");
    return 0;
  }
  std::atomic<int> polls{0};
};

}  // namespace

TEST_CASE("recording to a special file, a directory or an overlong path is refused", "[recording]") {
  Recorder recorder;
  std::string error;
  const std::string fifo = outputPath("fifo");
  ::unlink(fifo.c_str());
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  const auto start = std::chrono::steady_clock::now();
  CHECK_FALSE(recorder.open(fifo, DeviceSpec{}, error));  // used to block the command thread
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(2));
  CHECK(contains(error, "not a regular file"));
  CHECK_FALSE(recorder.open("/dev/full", DeviceSpec{}, error));  // every write would fail
  INFO(error);
  CHECK(contains(error, "not a regular file"));
  CHECK_FALSE(recorder.open(KF_TEST_OUTPUT_DIR, DeviceSpec{}, error));
  CHECK(contains(error, "directory"));
  CHECK_FALSE(recorder.open(outputPath(std::string(5000, 'x')), DeviceSpec{}, error));
  CHECK(contains(error, "File name too long"));
  CHECK_FALSE(recorder.isOpen());
  ::unlink(fifo.c_str());
}

TEST_CASE("one writer per file, under any path", "[recording]") {
  const std::string path = outputPath("shared.txt");
  const std::string link = outputPath("shared-link.txt");
  ::unlink(link.c_str());
  Recorder first, second;
  std::string error;
  REQUIRE(first.open(path, DeviceSpec{}, error));
  first.writeOff(0.5, OffCause::kClose);
  REQUIRE(first.flush());
  CHECK_FALSE(second.open(path, DeviceSpec{}, error));
  CHECK(contains(error, "another device is recording to this file"));
  REQUIRE(::symlink(path.c_str(), link.c_str()) == 0);
  CHECK_FALSE(second.open(link, DeviceSpec{}, error));
  // The refused open did not truncate the file being written.
  CHECK(contains(readAll(path), "O 0.5 close\n"));

  // Two device slots recording to one file: the second is refused.
  auto a = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::none(), true);
  auto b = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::none(), true);
  first.close();
  REQUIRE(a->startRecording(path, error));
  CHECK_FALSE(b->startRecording(path, error));
  a->stopRecording();
  CHECK(b->startRecording(path, error));  // free again
  ::unlink(link.c_str());
}

TEST_CASE("a write error stops the recording, keeps what was written and is posted", "[recording]") {
  const std::string path = outputPath("full.txt");
  ::unlink(path.c_str());
  setDeviceMessageSink(collectMessage);
  takeMessages();
  {
    FileSizeLimit limit(4096);
    auto device = openSimDevice(DeviceSpec{}, SimParams{}, HandScript::speeds({{100.0, 5.0}}), true);
    std::string error;
    REQUIRE(device->startRecording(path, error));
    double timeS = 0.0;
    for (int i = 0; i < 2000 && device->recordingError().empty(); ++i) {
      timeS += 0.001;
      device->pushForceFrame(ForceFrame{timeS, 0.4f});
      device->pump(timeS);
    }
    const std::string why = device->recordingError();
    CHECK(contains(why, "File too large"));
    CHECK(contains(why, "recording stopped"));
    // Later pumps neither write nor post again.
    for (int i = 0; i < 10; ++i) device->pump(timeS += 0.001);
  }
  checkStoppedByWriteError(path, 4096);
  // What was written is readable.
  SessionData session;
  std::string error;
  REQUIRE(readSessionFile(path, DeviceSpec{}, session, error));
  CHECK(session.warning.empty());
  CHECK(session.frames.size() >= 10);
}

TEST_CASE("an exception on the device thread drives the magnet off and is posted", "[recording][exit]") {
  setDeviceMessageSink(collectMessage);
  takeMessages();
  auto mouse = std::make_shared<ThrowingMouse>();
  auto force = std::make_shared<CountingForce>();
  Device device(DeviceSpec{}, mouse, force, false);
  const std::string path = outputPath("failure.txt");
  std::string error;
  REQUIRE(device.startRecording(path, error));
  device.start();
  // The thread drives the magnet off, then posts: its message says it has done both.
  std::vector<std::string> messages;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (messages.empty() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    messages = takeMessages();
  }
  CHECK(force->offs.load() == 1);
  CHECK(device.telemetry().lastCommandedForceN == Approx(DeviceSpec{}.minForceN));
  CHECK(device.threadFailed());  // what kfStatus reports as its fault
  REQUIRE(messages.size() == 1);
  CHECK(contains(messages[0], "driver lost the device"));
  device.close();  // joins the ended thread
  SessionData session;
  REQUIRE(readSessionFile(path, DeviceSpec{}, session, error));
  REQUIRE(session.offs.size() == 1);  // the recording ended with the failure
  CHECK(session.offs[0].cause == "failure");
  setDeviceMessageSink(nullptr);
}

TEST_CASE("emergencyOff: magnet off and an off record, without a lock", "[recording][exit]") {
  const std::string path = outputPath("emergency.txt");
  auto force = std::make_shared<CountingForce>();
  auto sim = std::make_shared<SimDevice>(DeviceSpec{}, SimParams{}, HandScript::none());
  Device device(DeviceSpec{}, sim, force, true);
  std::string error;
  REQUIRE(device.startRecording(path, error));
  for (int i = 1; i <= 1500; ++i) {
    device.pushForceFrame(ForceFrame{i * 0.001, 1.4f});
    device.pump(i * 0.001);
  }
  device.emergencyOff();
  CHECK(force->signalOffs.load() == 1);
  const std::string text = readAll(path);
  CHECK(contains(text, "\nO 1.500000000 signal\n"));
  SessionData session;
  REQUIRE(readSessionFile(path, DeviceSpec{}, session, error));
  REQUIRE(session.offs.size() == 1);
  CHECK(session.offs[0].hostTimeS == Approx(1.5));
  CHECK(session.offs[0].cause == "signal");
  CHECK(session.frames.back().commandedForceN == Approx(1.4f));
}

namespace {

// The names of this process's threads (/proc/self/task/*/comm).
std::vector<std::string> threadNames() {
  std::vector<std::string> names;
  DIR* tasks = ::opendir("/proc/self/task");
  if (!tasks) return names;
  while (dirent* entry = ::readdir(tasks)) {
    if (entry->d_name[0] == '.') continue;
    std::ifstream comm(std::string("/proc/self/task/") + entry->d_name + "/comm");
    std::string name;
    std::getline(comm, name);
    names.push_back(name);
  }
  ::closedir(tasks);
  return names;
}

bool hasThread(const std::string& name) {
  for (const std::string& each : threadNames())
    if (each == name) return true;
  return false;
}

}  // namespace

TEST_CASE("a realtime device's recording is written by a thread of its own, completely", "[recording]") {
  const std::string path = outputPath("threaded.txt");
  DeviceOptions options;
  options.thread.slot = 7;
  auto sim = std::make_shared<SimDevice>(DeviceSpec{}, SimParams{}, HandScript::speeds({{100.0, 5.0}}));
  Device device(DeviceSpec{}, sim, sim, false, options);
  device.start();
  std::string error;
  REQUIRE(device.startRecording(path, error));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  CHECK(hasThread("kf-rec-7"));  // named as it starts: by now
  device.stopRecording();
  CHECK_FALSE(hasThread("kf-rec-7"));  // finished with its recording
  const TelemetrySnapshot telemetry = device.telemetry();
  device.close();
  SessionData session;
  REQUIRE(readSessionFile(path, DeviceSpec{}, session, error));
  CHECK(session.warning.empty());
  // Every report the device thread received while recording is in the file: at 125 Hz, 300 ms
  // holds about 37 of them, and the device counted no more than that in its whole life.
  CHECK(session.reports.size() >= 30);
  CHECK(session.reports.size() <= telemetry.reports);
  for (size_t i = 1; i < session.reports.size(); ++i)
    CHECK(session.reports[i].hostTimeS >= session.reports[i - 1].hostTimeS);
}

TEST_CASE("a signal handler's off record is the last line: the writer thread writes nothing after it",
          "[recording][exit]") {
  // A threaded writer holds the lines handed to it until its next wake-up (every 10 ms). A
  // signal handler's off record, appended meanwhile, must stay the last line: the held lines are
  // lost with the process, never written after it (the ASan exit-signal test found frames after
  // the record, 2 turns in ~150).
  const std::string path = outputPath("sealed.txt");
  std::string error;
  Recorder recorder;
  recorder.attach(RecordingWriter::open(path, sessionHeader(DeviceSpec{}), true, 6, error));
  REQUIRE(recorder.isOpen());
  for (int i = 1; i <= 5; ++i) recorder.writeFrame(i * 0.001, ForceFrame{i * 0.001, 1.0f}, 1.0f);
  REQUIRE(recorder.flush());  // handed to the writer thread, which has not woken yet
  recorder.appendOffFromSignal(0.0055);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));  // three of the writer's periods
  recorder.close();
  std::string text = readAll(path);
  while (!text.empty() && text.back() == '\n') text.pop_back();
  CHECK(text.substr(text.rfind('\n') + 1) == "O 0.005500000 signal");
}

TEST_CASE("a realtime device's write error is posted once and the file keeps whole lines", "[recording]") {
  const std::string path = outputPath("threaded-full.txt");
  ::unlink(path.c_str());
  setDeviceMessageSink(collectMessage);
  takeMessages();
  {
    FileSizeLimit limit(4096);
    auto sim = std::make_shared<SimDevice>(DeviceSpec{}, SimParams{}, HandScript::speeds({{100.0, 5.0}}));
    Device device(DeviceSpec{}, sim, sim, false);
    device.start();
    std::string error;
    REQUIRE(device.startRecording(path, error));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    for (int frame = 0; device.recordingError().empty() && std::chrono::steady_clock::now() < deadline; ++frame) {
      device.pushForceFrame(ForceFrame{device.nowS(), 0.4f});
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    CHECK(contains(device.recordingError(), "File too large"));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // later pumps post nothing more
    device.stopRecording();
    device.close();
  }
  checkStoppedByWriteError(path, 4096);
  // Another recording may have the file at once.
  Recorder again;
  std::string error;
  CHECK(again.open(path, DeviceSpec{}, error));
}

TEST_CASE("a disk that falls behind stops the recording instead of the device thread", "[recording]") {
  const std::string path = outputPath("behind.txt");
  std::string error;
  std::unique_ptr<RecordingWriter> writer = RecordingWriter::open(path, "header\n", true, 0, error);
  REQUIRE(writer);
  std::string lines = "R 1\n";
  REQUIRE(writer->hand(lines));
  CHECK(lines.empty());
  // More than the queue holds in one hand-over, even empty: as a disk that stalled for half a
  // minute. (A flood of exactly the queue's size fitted whenever the writer had taken "R 1"
  // meanwhile: it writes every 10 ms, and a loaded machine let it in between.)
  std::string flood(RecordingWriter::kQueueBytes + 1, 'x');
  flood.back() = '\n';
  CHECK_FALSE(writer->hand(flood));
  CHECK(contains(writer->error(), "MiB behind"));
  lines = "R 2\n";
  CHECK_FALSE(writer->hand(lines));  // stopped for good
  writer->finish();
  CHECK(writer->failed());
  CHECK(contains(writer->error(), "recording stopped"));
  CHECK(readAll(path) == "header\nR 1\n");  // what came before is kept, and nothing after
}
