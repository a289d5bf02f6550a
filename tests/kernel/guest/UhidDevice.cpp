#include "UhidDevice.hpp"

#include <fcntl.h>
#include <linux/uhid.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace kf::guest {

namespace {
void writeEvent(int fd, const uhid_event& event) {
  const ssize_t n = ::write(fd, &event, sizeof(event));
  if (n != static_cast<ssize_t>(sizeof(event)))
    throw std::runtime_error(std::string("uhid write: ") + (n < 0 ? std::strerror(errno) : "short write"));
}
}  // namespace

UhidDevice::UhidDevice(const UhidIdentity& identity, const std::vector<uint8_t>& descriptor) {
  fd_ = ::open("/dev/uhid", O_RDWR | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error(std::string("/dev/uhid: ") + std::strerror(errno) + " (is uhid loaded?)");
  if (descriptor.size() > HID_MAX_DESCRIPTOR_SIZE) throw std::runtime_error("report descriptor too long for uhid");
  uhid_event event{};
  event.type = UHID_CREATE2;
  std::strncpy(reinterpret_cast<char*>(event.u.create2.name), identity.name.c_str(), sizeof(event.u.create2.name) - 1);
  std::strncpy(reinterpret_cast<char*>(event.u.create2.uniq), identity.uniq.c_str(), sizeof(event.u.create2.uniq) - 1);
  std::strncpy(reinterpret_cast<char*>(event.u.create2.phys), "kf-guest", sizeof(event.u.create2.phys) - 1);
  event.u.create2.rd_size = static_cast<uint16_t>(descriptor.size());
  event.u.create2.bus = identity.bus;
  event.u.create2.vendor = identity.vendorId;
  event.u.create2.product = identity.productId;
  std::memcpy(event.u.create2.rd_data, descriptor.data(), descriptor.size());
  try {
    writeEvent(fd_, event);
  } catch (...) {
    ::close(fd_);
    throw;
  }
  thread_ = std::thread([this] { answerRequests(); });
}

UhidDevice::~UhidDevice() {
  uhid_event event{};
  event.type = UHID_DESTROY;
  try {
    writeEvent(fd_, event);
  } catch (...) {
  }
  stop_ = true;
  thread_.join();
  ::close(fd_);
}

void UhidDevice::send(const std::vector<uint8_t>& report) { send(report.data(), report.size()); }

void UhidDevice::send(const uint8_t* bytes, size_t size) {
  uhid_event event{};
  event.type = UHID_INPUT2;
  if (size > sizeof(event.u.input2.data)) throw std::runtime_error("input report too long for uhid");
  event.u.input2.size = static_cast<uint16_t>(size);
  std::memcpy(event.u.input2.data, bytes, size);
  writeEvent(fd_, event);
}

void UhidDevice::answerRequests() {
  while (!stop_) {
    pollfd ready{fd_, POLLIN, 0};
    if (::poll(&ready, 1, 20) <= 0) continue;
    uhid_event event{};
    if (::read(fd_, &event, sizeof(event)) <= 0) continue;
    if (event.type == UHID_START) started_ = true;
    uhid_event reply{};
    if (event.type == UHID_GET_REPORT) {
      reply.type = UHID_GET_REPORT_REPLY;
      reply.u.get_report_reply.id = event.u.get_report.id;
      reply.u.get_report_reply.err = EIO;
    } else if (event.type == UHID_SET_REPORT) {
      reply.type = UHID_SET_REPORT_REPLY;
      reply.u.set_report_reply.id = event.u.set_report.id;
      reply.u.set_report_reply.err = EIO;
    } else {
      continue;
    }
    ::write(fd_, &reply, sizeof(reply));
  }
}

}  // namespace kf::guest
