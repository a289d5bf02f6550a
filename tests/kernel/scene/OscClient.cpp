#include "scene/OscClient.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace kf::guest {

namespace {

// OSC strings: NUL-terminated, padded to 4 bytes; numbers big-endian.
void putString(std::string& out, const std::string& text) {
  out += text;
  out.push_back('\0');
  while (out.size() % 4) out.push_back('\0');
}
void putInt(std::string& out, int32_t value) {
  const uint32_t be = htonl(static_cast<uint32_t>(value));
  out.append(reinterpret_cast<const char*>(&be), 4);
}
size_t skipString(const std::string& in, size_t at) {
  const size_t end = in.find('\0', at);
  if (end == std::string::npos) throw std::runtime_error("OSC: a string without its end");
  return (end + 4) & ~size_t{3};
}
uint32_t getWord(const std::string& in, size_t at) {
  if (at + 4 > in.size()) throw std::runtime_error("OSC: a message cut short");
  uint32_t be = 0;
  std::memcpy(&be, in.data() + at, 4);
  return ntohl(be);
}

}  // namespace

OscClient::OscClient(int port) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in server{};
  server.sin_family = AF_INET;
  server.sin_port = htons(static_cast<uint16_t>(port));
  server.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd_ < 0 || ::connect(fd_, reinterpret_cast<sockaddr*>(&server), sizeof server) != 0)
    throw std::runtime_error("OSC: cannot reach scsynth on port " + std::to_string(port));
}

OscClient::~OscClient() {
  if (fd_ >= 0) ::close(fd_);
}

std::vector<float> OscClient::controlBuses(int first, int count) {
  std::string message;
  putString(message, "/c_getn");
  putString(message, ",ii");
  putInt(message, first);
  putInt(message, count);
  if (::send(fd_, message.data(), message.size(), 0) != static_cast<ssize_t>(message.size()))
    throw std::runtime_error("OSC: send failed");
  for (;;) {
    pollfd fd{fd_, POLLIN, 0};
    if (::poll(&fd, 1, 5000) <= 0) throw std::runtime_error("scsynth did not answer /c_getn");
    char buffer[1024];
    const ssize_t got = ::recv(fd_, buffer, sizeof buffer, 0);
    if (got <= 0) throw std::runtime_error("OSC: receive failed");
    const std::string reply(buffer, static_cast<size_t>(got));
    if (reply.compare(0, 8, std::string("/c_setn\0", 8)) != 0) continue;  // another reply
    size_t at = skipString(reply, 0);
    const size_t tags = at;
    at = skipString(reply, at);
    // ,iif...: first bus, count, then the values
    if (reply.compare(tags, 3, ",ii") != 0) throw std::runtime_error("OSC: an unexpected /c_setn");
    at += 8;
    std::vector<float> values;
    for (int i = 0; i < count; ++i) {
      const uint32_t word = getWord(reply, at + 4 * static_cast<size_t>(i));
      float value = 0.0f;
      std::memcpy(&value, &word, 4);
      values.push_back(value);
    }
    return values;
  }
}

}  // namespace kf::guest
