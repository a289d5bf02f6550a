#include "HostHook.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <mutex>
#include <stdexcept>

namespace kf::guest {

namespace {
std::mutex hookMutex;  // one question and its answer at a time
}

HostHook& HostHook::instance() {
  static HostHook hook;
  return hook;
}

HostHook::HostHook() {
  fd_ = ::open("/dev/ttyS1", O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error(std::string("host hook /dev/ttyS1: ") + std::strerror(errno));
  termios raw{};
  if (::tcgetattr(fd_, &raw) == 0) {
    ::cfmakeraw(&raw);
    ::tcsetattr(fd_, TCSANOW, &raw);
  }
}

std::string HostHook::ask(const std::string& word, const std::string& text) {
  std::lock_guard<std::mutex> lock(hookMutex);
  std::string line = word + " " + text;
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';  // one line each way (JSON takes any whitespace)
  line += "\n";
  for (size_t sent = 0; sent < line.size();) {
    const ssize_t n = ::write(fd_, line.data() + sent, line.size() - sent);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("host hook write: ") + std::strerror(errno));
    sent += static_cast<size_t>(n);
  }
  std::string answer;
  char c = 0;
  while (true) {
    const ssize_t n = ::read(fd_, &c, 1);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("host hook read: ") + std::strerror(errno));
    if (c == '\n') break;
    answer.push_back(c);
  }
  const std::string prefix = word + " ";
  if (answer.compare(0, prefix.size(), prefix) != 0) throw std::runtime_error("host hook: unexpected answer " + answer);
  return answer.substr(prefix.size());
}

std::string HostHook::qmp(const std::string& json) { return ask("qmp", json); }

void HostHook::qmpOrThrow(const std::string& json) {
  const std::string answer = qmp(json);
  if (answer.find("\"error\"") != std::string::npos) throw std::runtime_error("QMP " + json + ": " + answer);
}

std::string HostHook::host(const std::string& name, const std::string& argument) {
  return ask("host", name + " " + argument);
}

}  // namespace kf::guest
