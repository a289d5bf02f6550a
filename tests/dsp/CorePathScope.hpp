// For the dsp tests: run a test on each code path of the cores (dsp/CorePath.hpp).
#pragma once

#include <catch2/catch.hpp>

#include "CorePath.hpp"

// Runs the code path it is given for as long as it lives, then the one before it again.
struct PathScope {
  kf::CorePath before = kf::corePath(), used;
  explicit PathScope(kf::CorePath wanted) : used(kf::setCorePath(wanted)) {}
  ~PathScope() { kf::setCorePath(before); }
};

// A test with EACH_CORE_PATH runs once per code path (CorePath.hpp); on a processor without
// AVX2/FMA the avx2 run ends at once (setCorePath falls back to the portable path, run already).
#define EACH_CORE_PATH()                                                                \
  const kf::CorePath wantedPath = GENERATE(kf::CorePath::portable, kf::CorePath::avx2); \
  PathScope pathScope(wantedPath);                                                      \
  if (pathScope.used != wantedPath) return;                                             \
  INFO("core path " << kf::corePathName(pathScope.used))
