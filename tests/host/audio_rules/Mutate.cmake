# Writes a mutant of a plugin source for the audio-thread rules test: the same file with one
# forbidden call at the top of its UGen's calculation function (`void next(int numSamples) {`,
# which must occur exactly once).
#   cmake -DSOURCE=<plugin file> -DOUTPUT=<mutant> -DMUTATION=alloc|lock -P Mutate.cmake
if(MUTATION STREQUAL "alloc")
  set(header "#include <cstdlib>\n")
  set(code "    { void* volatile kfMutant = malloc(16); free(kfMutant); }\n")
elseif(MUTATION STREQUAL "lock")
  set(header "#include <mutex>\n")
  set(code "    { static std::mutex kfMutant; std::lock_guard<std::mutex> kfMutantLock(kfMutant); }\n")
else()
  message(FATAL_ERROR "Mutate.cmake: MUTATION must be alloc or lock, not '${MUTATION}'")
endif()
file(READ "${SOURCE}" text)
set(anchor "  void next(int numSamples) {\n")
string(FIND "${text}" "${anchor}" first)
string(FIND "${text}" "${anchor}" last REVERSE)
if(first EQUAL -1 OR NOT first EQUAL last)
  message(FATAL_ERROR "Mutate.cmake: ${SOURCE} has not exactly one '  void next(int numSamples) {'")
endif()
string(REPLACE "${anchor}" "${anchor}${code}" text "${text}")
file(WRITE "${OUTPUT}" "// A mutant of ${SOURCE} (tests/host/audio_rules/Mutate.cmake): ${MUTATION}.\n${header}${text}")
