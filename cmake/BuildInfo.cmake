# Run by `cmake --install` (install(CODE)): writes build-info.scd into the extension folder, the
# commit the installed classes and plugin came from, so that a study's manifest can name it
# (FrictionStudySession.provenance). Needs KF_SOURCE_DIR and KF_BUILD_INFO_PATH. Outside a git
# checkout (a release tarball) the commit is "unknown".
set(commit "unknown")
set(dirty "false")
find_program(KF_GIT git)
if(KF_GIT)
  execute_process(COMMAND ${KF_GIT} -C ${KF_SOURCE_DIR} rev-parse HEAD OUTPUT_VARIABLE head
                  RESULT_VARIABLE head_failed OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(NOT head_failed)
    set(commit ${head})
    # Changes to tracked files not committed: the commit alone does not say what was installed.
    execute_process(COMMAND ${KF_GIT} -C ${KF_SOURCE_DIR} status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE changes ERROR_QUIET)
    if(changes)
      set(dirty "true")
    endif()
  endif()
endif()
file(WRITE ${KF_BUILD_INFO_PATH} "// Written by cmake --install (cmake/BuildInfo.cmake).\n(commit: \"${commit}\", dirty: ${dirty})\n")
