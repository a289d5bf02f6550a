# Clang with LLVM's libc++ (Debian's clang, libc++-dev, libc++abi-dev): the C++ library macOS
# uses. With -DKF_PLATFORM=posix the platform code is the path macOS takes (cmake/Platform.cmake).
#   cmake -S . -B build-libcxx --toolchain cmake/toolchains/clang-libcxx.cmake -DKF_PLATFORM=posix
set(CMAKE_C_COMPILER clang)
set(CMAKE_CXX_COMPILER clang++)
set(CMAKE_CXX_FLAGS_INIT "-stdlib=libc++")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-stdlib=libc++")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-stdlib=libc++")
set(CMAKE_MODULE_LINKER_FLAGS_INIT "-stdlib=libc++")
