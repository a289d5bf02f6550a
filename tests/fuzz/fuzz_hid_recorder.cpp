// libFuzzer target: the hid-recorder text reader, then the whole replay path (descriptor,
// decoder, reports) as kfOpenReplay runs it.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "FuzzFile.hpp"
#include "recordings/HidRecorderFile.hpp"
#include "recordings/ReplayBackend.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = kf::fuzz::writeScratch(data, size);
  kf::HidRecording recording;
  std::string error, warning;
  (void)kf::readHidRecorderFile(path, recording, error);
  kf::DeviceSpec spec;
  std::vector<kf::TimedReport> reports;
  size_t skipped = 0;
  (void)kf::loadReplayReports(path, spec, reports, error, &skipped, &warning);
  return 0;
}
