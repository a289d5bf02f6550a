// How status names the device threads' scheduling on each system (kfStatus, FrictionDevice's
// status): test_thread_scheduling needs POSIX and is not built for Windows, so this one, which
// runs under Wine too (scripts/check.sh cross: its name must not start with "realtime", which
// Wine skips), checks the Windows name.
#include <catch2/catch.hpp>

#include "core/threads/ThreadScheduling.hpp"

using kf::describe;
using kf::ThreadScheduling;

TEST_CASE("status names the realtime scheduling as this system does", "[scheduling]") {
  const ThreadScheduling realtime{20, true};
#ifdef _WIN32
  CHECK(describe(realtime) == "time-critical, memory locked");  // one level: no number
#else
  CHECK(describe(realtime) == "SCHED_FIFO 20, memory locked");
#endif
  CHECK(describe(ThreadScheduling{0, false}) == "normal priority");
  CHECK(describe(ThreadScheduling{}) == "not started");
}
