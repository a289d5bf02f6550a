#include "scene/AudioServer.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "guest/GuestSystem.hpp"

namespace kf::guest {

namespace {

std::string resultsDir() {
  const char* folder = std::getenv("KF_GUEST_RESULTS");
  return folder ? folder : "/tmp";
}

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Starts argv with stdout and stderr into `log` and the environment's additions.
pid_t spawn(std::vector<std::string> argv, const std::string& log, const std::vector<std::string>& env) {
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork");
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
    for (const std::string& assignment : env) ::putenv(const_cast<char*>(assignment.c_str()));
    std::vector<char*> raw;
    for (std::string& word : argv) raw.push_back(word.data());
    raw.push_back(nullptr);
    ::execv(raw[0], raw.data());
    ::_exit(127);
  }
  return pid;
}

void stop(pid_t& pid) {
  if (pid <= 0) return;
  ::kill(pid, SIGTERM);
  int status = 0;
  if (!waitUntil([&] { return ::waitpid(pid, &status, WNOHANG) == pid; }, 10.0)) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
  }
  pid = -1;
}

}  // namespace

void networkUp() {
  if (std::system("ip link set lo up && ip link set eth0 up && ip addr add 10.0.2.15/24 dev eth0 && "
                  "ip route add default via 10.0.2.2") != 0)
    throw std::runtime_error("the guest's network did not come up (is virtio_net loaded?)");
}

AudioServer::AudioServer(int udpPort) {
  // JACK keeps its shared memory and sockets in /dev/shm.
  ::mkdir("/dev/shm", 01777);
  if (::mount("tmpfs", "/dev/shm", "tmpfs", 0, nullptr) != 0 && errno != EBUSY)
    throw std::runtime_error("cannot mount /dev/shm");
  const std::string jackLog = resultsDir() + "/scene-jackd.log";
  const std::string scsynthLog = scsynthLog_ = resultsDir() + "/scene-scsynth.log";
  const std::vector<std::string> env{"JACK_NO_AUDIO_RESERVATION=1", "JACK_NO_START_SERVER=1",
                                     "SC_JACK_DEFAULT_INPUTS=", "SC_JACK_DEFAULT_OUTPUTS="};
  jackd_ = spawn({KF_JACKD, "-R", "-d", "dummy", "-r", "48000", "-p", std::to_string(kPeriodFrames)}, jackLog, env);
  const bool jackUp = waitUntil(
      [] {
        for (const auto& entry : std::filesystem::directory_iterator("/dev/shm"))
          if (entry.path().filename().string().rfind("jack_default", 0) == 0) return true;
        return false;
      },
      30.0);
  if (!jackUp) throw std::runtime_error("jackd did not start: " + readAll(jackLog));
  scsynth_ = spawn({KF_SCSYNTH, "-u", std::to_string(udpPort), "-B", "0.0.0.0", "-i", "2", "-o", "2", "-m", "65536",
                    "-Z", std::to_string(kPeriodFrames), "-R", "0", "-l", "8", "-U",
                    std::string(KF_SC_SYSTEM_PLUGINS) + ":" + KF_PLUGIN_DIR},
                   scsynthLog, env);
  const bool ready = waitUntil([&] { return readAll(scsynthLog).find("server ready") != std::string::npos; }, 60.0);
  if (!ready) throw std::runtime_error("scsynth did not start: " + readAll(scsynthLog));
}

std::string AudioServer::statusLine() const {
  std::istringstream log(readAll(scsynthLog_));
  std::string line, last;
  while (std::getline(log, line))
    if (line.rfind("kfStatus ", 0) == 0 && line.find(": realtime, ") != std::string::npos) last = line;
  return last;
}

AudioServer::~AudioServer() {
  stop(scsynth_);
  stop(jackd_);
}

}  // namespace kf::guest
