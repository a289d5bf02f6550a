#include "CorePath.hpp"

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace kf {

namespace {

// -1: not chosen yet. Relaxed: the value is one of two valid paths whichever a reader sees.
std::atomic<int> gPath{-1};

}  // namespace

const char* corePathName(CorePath path) { return path == CorePath::avx2 ? "avx2" : "portable"; }

bool cpuHasAvx2Fma() {
#if KF_CORE_AVX2
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

CorePath chooseCorePath(bool hasAvx2Fma, const char* request) {
  if (request && std::strcmp(request, "portable") == 0) return CorePath::portable;
  return hasAvx2Fma ? CorePath::avx2 : CorePath::portable;
}

CorePath corePath() {
  int p = gPath.load(std::memory_order_relaxed);
  if (p < 0) {
    p = static_cast<int>(chooseCorePath(cpuHasAvx2Fma(), std::getenv("KF_CORE_PATH")));
    gPath.store(p, std::memory_order_relaxed);
  }
  return static_cast<CorePath>(p);
}

CorePath setCorePath(CorePath wanted) {
  const CorePath p = chooseCorePath(cpuHasAvx2Fma(), wanted == CorePath::portable ? "portable" : nullptr);
  gPath.store(static_cast<int>(p), std::memory_order_relaxed);
  return p;
}

}  // namespace kf
