#include "core/threads/DeviceMessages.hpp"

#include <atomic>
#include <cstdio>

namespace kf {

namespace {
std::atomic<DeviceMessageSink> gSink{nullptr};
}  // namespace

void setDeviceMessageSink(DeviceMessageSink sink) { gSink.store(sink, std::memory_order_release); }

void postDeviceMessage(const char* message) {
  if (DeviceMessageSink sink = gSink.load(std::memory_order_acquire))
    sink(message);
  else
    std::fprintf(stderr, "%s\n", message);
}

}  // namespace kf
