#include "GuestSystem.hpp"

#include <fcntl.h>
#include <grp.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace kf::guest {

namespace {
std::string readLine(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}
}  // namespace

std::map<std::string, std::string> udevProperties(const std::string& node) {
  std::map<std::string, std::string> out;
  const std::string command = "udevadm info --query=property --name=" + node + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("popen " + command);
  char line[4096];
  while (std::fgets(line, sizeof(line), pipe)) {
    std::string text = line;
    if (!text.empty() && text.back() == '\n') text.pop_back();
    const size_t equals = text.find('=');
    if (equals != std::string::npos) out[text.substr(0, equals)] = text.substr(equals + 1);
  }
  ::pclose(pipe);
  return out;
}

std::string udevTags(const std::string& node) {
  const auto properties = udevProperties(node);
  auto current = properties.find("CURRENT_TAGS");
  if (current != properties.end()) return current->second;
  auto tags = properties.find("TAGS");
  return tags == properties.end() ? std::string() : tags->second;
}

void udevSettle() {
  if (std::system("udevadm settle --timeout=60") != 0) throw std::runtime_error("udevadm settle failed");
}

int openAsSeatUser(const std::string& path, int flags) {
  const pid_t child = ::fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    if (::setgroups(0, nullptr) != 0 || ::setgid(kSeatUid) != 0 || ::setuid(kSeatUid) != 0) ::_exit(250);
    const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
    ::_exit(fd >= 0 ? 0 : errno);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) == 250) throw std::runtime_error("could not become the seat user");
  return WEXITSTATUS(status);
}

bool waitUntil(const std::function<bool()>& done, double hangGuardS) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(hangGuardS);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

void reportFigure(const std::string& test, const std::string& text) {
  const char* folder = std::getenv("KF_GUEST_RESULTS");
  std::ofstream out(std::string(folder ? folder : "/tmp") + "/figures.txt", std::ios::app);
  out << test << ": " << text << "\n";
}

std::vector<std::string> eventNodesNamed(const std::string& name) {
  std::vector<std::string> nodes;
  for (const auto& entry : std::filesystem::directory_iterator("/sys/class/input")) {
    const std::string node = entry.path().filename().string();
    if (node.rfind("event", 0) == 0 && readLine(entry.path().string() + "/device/name") == name)
      nodes.push_back("/dev/input/" + node);
  }
  return nodes;
}

std::vector<std::string> hidrawNodesNamed(const std::string& name) {
  std::vector<std::string> nodes;
  if (!std::filesystem::exists("/sys/class/hidraw")) return nodes;
  for (const auto& entry : std::filesystem::directory_iterator("/sys/class/hidraw")) {
    std::ifstream uevent(entry.path().string() + "/device/uevent");
    std::string line;
    while (std::getline(uevent, line))
      if (line == "HID_NAME=" + name) nodes.push_back("/dev/" + entry.path().filename().string());
  }
  return nodes;
}

}  // namespace kf::guest
