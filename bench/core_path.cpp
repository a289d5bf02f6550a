// Prints the code path the signal cores take (dsp/CorePath.hpp) in this environment
// (KF_CORE_PATH) on this processor: the one a scsynth started with the same environment runs.
// The bench records it beside each part's figures.
#include <cstdio>

#include "CorePath.hpp"

int main() {
  std::printf("path %s\n", kf::corePathName(kf::corePath()));
  std::printf("avx2_fma %s\n", kf::cpuHasAvx2Fma() ? "yes" : "no");
  return 0;
}
