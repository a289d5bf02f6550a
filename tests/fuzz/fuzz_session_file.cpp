// libFuzzer target: the kf-session reader (header fields through the bounds table, records,
// a last line cut), and the replay loader that picks the format by the first line.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "FuzzFile.hpp"
#include "core/files/SessionFile.hpp"
#include "recordings/ReplayBackend.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = kf::fuzz::writeScratch(data, size);
  kf::SessionData session;
  std::string error;
  if (kf::readSessionFile(path, kf::DeviceSpec{}, session, error) && !session.spec.isValid()) __builtin_trap();
  kf::DeviceSpec spec;
  std::vector<kf::TimedReport> reports;
  std::string warning;
  if (kf::loadReplayReports(path, spec, reports, error, nullptr, &warning) && !spec.isValid()) __builtin_trap();
  return 0;
}
