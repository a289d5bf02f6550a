// What ThreadSchedulingPosix.cpp (shared by every POSIX system) asks of the file of its system
// (ThreadSchedulingLinux.cpp, ThreadSchedulingPosixGeneric.cpp).
#pragma once

namespace kf {

// Names the calling thread (at most 15 characters are kept on Linux).
void nameThisThread(const char* name);

}  // namespace kf
