# -DKF_EXTENSION_DIR=user: cmake --install puts the extension where SuperCollider looks for the
# user's extensions (Platform.userExtensionDir), in a folder KineticFriction:
#   Linux    $XDG_DATA_HOME/SuperCollider/Extensions (default ~/.local/share/...)
#   macOS    ~/Library/Application Support/SuperCollider/Extensions
#   Windows  %LOCALAPPDATA%\SuperCollider\Extensions
# Read on the machine that configures, for the system the build is for (a cross build has no
# user of its own there: give the path instead).
if(KF_EXTENSION_DIR STREQUAL "user")
  if(CMAKE_CROSSCOMPILING)
    message(FATAL_ERROR "KF_EXTENSION_DIR=user needs a native build; give the Extensions folder's path instead")
  elseif(WIN32)
    file(TO_CMAKE_PATH "$ENV{LOCALAPPDATA}/SuperCollider/Extensions" kf_user_extensions)
  elseif(APPLE)
    set(kf_user_extensions "$ENV{HOME}/Library/Application Support/SuperCollider/Extensions")
  elseif(DEFINED ENV{XDG_DATA_HOME} AND NOT "$ENV{XDG_DATA_HOME}" STREQUAL "")
    set(kf_user_extensions "$ENV{XDG_DATA_HOME}/SuperCollider/Extensions")
  else()
    set(kf_user_extensions "$ENV{HOME}/.local/share/SuperCollider/Extensions")
  endif()
  set(KF_EXTENSION_DIR "${kf_user_extensions}/KineticFriction" CACHE STRING
      "Extension folder that install() fills with the plugin, classes and help (user: the user's Extensions)" FORCE)
  message(STATUS "Extension folder: ${KF_EXTENSION_DIR}")
endif()
if(NOT IS_ABSOLUTE "${KF_EXTENSION_DIR}")
  # Relative to the build folder (install() would take it relative to the install prefix).
  get_filename_component(kf_extension_dir "${KF_EXTENSION_DIR}" ABSOLUTE BASE_DIR "${CMAKE_BINARY_DIR}")
  set(KF_EXTENSION_DIR "${kf_extension_dir}" CACHE STRING
      "Extension folder that install() fills with the plugin, classes and help (user: the user's Extensions)" FORCE)
endif()
