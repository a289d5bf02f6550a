# The system the platform code is built for, one file per platform (ARCHITECTURE.md, "Platforms"):
#   *Linux.cpp          Linux only
#   *Posix.cpp          every POSIX system (Linux and the others)
#   *PosixGeneric.cpp   a POSIX system other than Linux: the path macOS takes
#   *Windows.cpp        Windows
#   *NotLinux.cpp       every system but Linux
# KF_PLATFORM=posix on Linux builds the macOS path here (scripts/check.sh cross, with clang and
# libc++). KF_WITH_HARDWARE=OFF leaves hidapi and libusb out (mouse/HidapiIoAbsent.cpp,
# board/LibusbPortAbsent.cpp answer instead): Debian ships neither for MinGW.
if(WIN32)
  set(kf_platform_default windows)
elseif(CMAKE_SYSTEM_NAME STREQUAL "Linux")
  set(kf_platform_default linux)
else()
  set(kf_platform_default posix)
endif()
set(KF_PLATFORM ${kf_platform_default} CACHE STRING "Platform code: linux, posix (macOS's path) or windows")
set_property(CACHE KF_PLATFORM PROPERTY STRINGS linux posix windows)
option(KF_WITH_HARDWARE "Real mice (hidapi) and the friction board (libusb)" ON)

set(kf_platform_linux Linux Posix)
set(kf_platform_posix Posix PosixGeneric NotLinux)
set(kf_platform_windows Windows NotLinux)
if(NOT DEFINED kf_platform_${KF_PLATFORM})
  message(FATAL_ERROR "KF_PLATFORM must be linux, posix or windows, not '${KF_PLATFORM}'")
endif()

# kf_platform_sources(<list variable>): keeps, of the sources in the list, the platform files of
# KF_PLATFORM and the hardware backends or their absent stand-ins as KF_WITH_HARDWARE says.
function(kf_platform_sources sources_var)
  set(kept)
  foreach(source IN LISTS ${sources_var})
    get_filename_component(name ${source} NAME_WE)
    if(name MATCHES "(NotLinux|Linux|PosixGeneric|Posix|Windows)$")
      if(NOT CMAKE_MATCH_1 IN_LIST kf_platform_${KF_PLATFORM})
        continue()
      endif()
    endif()
    if(KF_WITH_HARDWARE AND name MATCHES "Absent$")
      continue()
    endif()
    if(NOT KF_WITH_HARDWARE AND name MATCHES "^(HidapiIo|LibusbPort)$")
      continue()
    endif()
    list(APPEND kept ${source})
  endforeach()
  set(${sources_var} ${kept} PARENT_SCOPE)
endfunction()
