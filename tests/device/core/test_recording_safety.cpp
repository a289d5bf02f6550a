// Issue 13, items 3 and 4 (device side): recordings never fail silently — write errors stop
// the recording cleanly with what was written kept, and are posted; special files and a
// second writer of one file are refused. The magnet goes off when the device thread dies of
// an exception, and from a signal handler (emergencyOff) with an off record appended.
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
#include "core/DeviceMessages.hpp"
#include "core/files/SessionFile.hpp"
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
  first.writeOff(0.5);
  REQUIRE(first.flush());
  CHECK_FALSE(second.open(path, DeviceSpec{}, error));
  CHECK(contains(error, "another device is recording to this file"));
  REQUIRE(::symlink(path.c_str(), link.c_str()) == 0);
  CHECK_FALSE(second.open(link, DeviceSpec{}, error));
  // The refused open did not truncate the file being written.
  CHECK(contains(readAll(path), "O 0.5\n"));

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
  const std::vector<std::string> messages = takeMessages();
  REQUIRE(messages.size() == 1);
  CHECK(contains(messages[0], "kfRecord: writing "));
  setDeviceMessageSink(nullptr);
  // What was written is whole lines, all of them readable.
  const std::string text = readAll(path);
  CHECK(text.size() <= 4096);
  REQUIRE(!text.empty());
  CHECK(text.back() == '\n');
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
  device.start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (force->offs.load() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  CHECK(force->offs.load() == 1);
  CHECK(device.telemetry().lastCommandedForceN == Approx(DeviceSpec{}.minForceN));
  const std::vector<std::string> messages = takeMessages();
  REQUIRE(messages.size() == 1);
  CHECK(contains(messages[0], "driver lost the device"));
  device.close();  // joins the ended thread
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
  CHECK(contains(text, "\nO 1.500000000\n"));
  SessionData session;
  REQUIRE(readSessionFile(path, DeviceSpec{}, session, error));
  REQUIRE(session.offTimesS.size() == 1);
  CHECK(session.offTimesS[0] == Approx(1.5));
  CHECK(session.frames.back().commandedForceN == Approx(1.4f));
}
