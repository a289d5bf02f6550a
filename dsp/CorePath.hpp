// Which code path the signal cores (LoudnessToFriction, the spatial reader) run: the portable one
// (SSE2 on x86-64, plain C++ elsewhere) or the AVX2/FMA one, chosen at run time so that one
// binary runs on every x86-64 processor and uses the wider units where they exist.
#pragma once

// KF_CORE_AVX2: this build has the AVX2/FMA path (GCC or Clang on x86-64, where its functions are
// compiled with __attribute__((target("avx2,fma"))) and only called after the processor check).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define KF_CORE_AVX2 1
#else
#define KF_CORE_AVX2 0
#endif

namespace kf {

enum class CorePath { portable, avx2 };

const char* corePathName(CorePath path);  // "portable" or "avx2"

// Whether this processor runs AVX2 and FMA (false on builds that have no AVX2 path).
bool cpuHasAvx2Fma();

// The path for a processor with or without AVX2/FMA, given the KF_CORE_PATH environment value
// (null when unset): "portable" forces the portable path; anything else asks for the fastest,
// which is AVX2 only where the processor has it.
CorePath chooseCorePath(bool hasAvx2Fma, const char* request);

// The path the cores run now: chooseCorePath(cpuHasAvx2Fma(), getenv("KF_CORE_PATH")) at the
// first call, until setCorePath.
CorePath corePath();

// For tests and the bench: run `wanted` from now on, where the processor can (AVX2 falls back
// to portable without it). Returns the path now in use. Not for use while a core is processing
// in another thread: the choice is process-wide.
CorePath setCorePath(CorePath wanted);

}  // namespace kf
