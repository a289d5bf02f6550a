# Windows x86-64 from Debian's MinGW-w64 cross compiler (g++-mingw-w64-x86-64-posix: the posix
# threading model, which std::thread and std::mutex need; the win32 one has neither in GCC 12).
#   cmake -S . -B build-mingw --toolchain cmake/toolchains/mingw-w64-x86_64.cmake -DKF_WITH_HARDWARE=OFF
# Executables link libgcc, libstdc++ and winpthread statically, so Wine (and a Windows machine)
# runs them without those DLLs beside them; ctest runs them through wine when it is installed.
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(CMAKE_C_COMPILER x86_64-w64-mingw32-gcc-posix)
set(CMAKE_CXX_COMPILER x86_64-w64-mingw32-g++-posix)
set(CMAKE_RC_COMPILER x86_64-w64-mingw32-windres)
set(CMAKE_FIND_ROOT_PATH /usr/x86_64-w64-mingw32)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
# Header-only packages of the build machine serve any target: Catch2 v2, the SC plugin headers.
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
# MinGW's own printf family (C99: %zu, %lld) rather than the old msvcrt's.
set(CMAKE_C_FLAGS_INIT "-D__USE_MINGW_ANSI_STDIO=1")
set(CMAKE_CXX_FLAGS_INIT "-D__USE_MINGW_ANSI_STDIO=1")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-static-libgcc -static-libstdc++ -Wl,-Bstatic,--whole-archive -lwinpthread -Wl,--no-whole-archive")
set(CMAKE_MODULE_LINKER_FLAGS_INIT "${CMAKE_SHARED_LINKER_FLAGS_INIT}")
# Wine with a prefix of the build's own (made on first use, a few seconds), no debug output and
# no Mono or Gecko install prompts (mscoree, mshtml disabled): the tests need neither.
find_program(KF_WINE NAMES wine64 wine PATHS /usr/lib/wine)
if(KF_WINE)
  set(CMAKE_CROSSCOMPILING_EMULATOR env WINEPREFIX=${CMAKE_BINARY_DIR}/wine-prefix WINEDEBUG=-all
                                    WINEDLLOVERRIDES=mscoree,mshtml= ${KF_WINE})
endif()
