// libFuzzer target: the plugin commands' argument reader on an OSC message body (",tags\0..."
// then the data), for every command shape. It must never read outside the input (AddressSanitizer
// sees the input's exact extent) and accept only what it checked.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "CommandArgs.hpp"

namespace {
double gValues[kf::sc::kMaxHandValues];
double* storage(void*, int count) { return count <= kf::sc::kMaxHandValues ? gValues : nullptr; }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // A copy of exactly `size` bytes on the heap: any read past it is reported.
  std::vector<char> message(data, data + size);
  using kf::sc::CommandShape;
  for (CommandShape shape : {CommandShape::kIndex, CommandShape::kStatus, CommandShape::kOpenSim,
                             CommandShape::kOpenReplay, CommandShape::kRecord, CommandShape::kHeartbeat}) {
    kf::sc::OscArgReader reader = kf::sc::OscArgReader::fromMessage(message.data(), message.size());
    kf::sc::CommandArgs args;
    char error[200];
    if (!kf::sc::parseCommandArgs(shape, reader, 16, args, storage, nullptr, error, sizeof error)) continue;
    // Accepted: the index is a slot, strings are terminated within their arrays.
    if (args.index < 0 || args.index > 15) __builtin_trap();
    if (std::memchr(args.path, '\0', sizeof args.path) == nullptr) __builtin_trap();
    if (args.numOverrides < 0 || args.numOverrides > kf::sc::kMaxOverrides) __builtin_trap();
    for (int i = 0; i < args.numOverrides; ++i)
      if (std::memchr(args.keys[i], '\0', sizeof args.keys[i]) == nullptr) __builtin_trap();
  }
  return 0;
}
