// The file readers take paths: each fuzz input is written to one scratch file per process.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace kf::fuzz {

// Removed when the fuzzer exits (libFuzzer ends a bounded run with exit(), which runs static
// destructors): each run left one file per target in /tmp. After a crash it stays, as the input.
struct ScratchFile {
  std::string path = "/tmp/kf-fuzz-input-" + std::to_string(::getpid());
  ~ScratchFile() { std::remove(path.c_str()); }
};

inline const std::string& scratchPath() {
  static const ScratchFile file;
  return file.path;
}

inline const std::string& writeScratch(const uint8_t* data, size_t size) {
  std::FILE* file = std::fopen(scratchPath().c_str(), "wb");
  if (file != nullptr) {
    if (size > 0) std::fwrite(data, 1, size, file);
    std::fclose(file);
  }
  return scratchPath();
}

}  // namespace kf::fuzz
