# Run by cmake --install after the classes are installed (CMakeLists.txt): removes every *.sc file
# of the installed Classes folder that this install did not put there, and the folders it leaves
# empty. A class file moved to another folder or renamed since an earlier install would otherwise
# stay beside its new copy, and sclang stops at the duplicate class. The files that belong are
# sc-classes/'s *.sc at their place and the generated ones (KF_GENERATED_CLASSES, relative to
# Classes/); anything else in the folder (not a class file) is left alone.
#   KF_CLASSES_DIR        the installed Classes folder
#   KF_CLASS_SOURCE_DIR   sc-classes/ of the source tree
#   KF_GENERATED_CLASSES  the generated class files, relative to Classes/ (PaperProfile.sc, UGens/...)
file(GLOB_RECURSE kf_sources RELATIVE "${KF_CLASS_SOURCE_DIR}" "${KF_CLASS_SOURCE_DIR}/*.sc")
set(kf_expected ${kf_sources} ${KF_GENERATED_CLASSES})
file(GLOB_RECURSE kf_installed RELATIVE "${KF_CLASSES_DIR}" "${KF_CLASSES_DIR}/*.sc")
foreach(kf_file IN LISTS kf_installed)
  list(FIND kf_expected "${kf_file}" kf_at)
  if(kf_at EQUAL -1)
    message(STATUS "Removing (no longer installed here): ${KF_CLASSES_DIR}/${kf_file}")
    file(REMOVE "${KF_CLASSES_DIR}/${kf_file}")
  endif()
endforeach()
# The folders left empty, deepest first.
file(GLOB_RECURSE kf_folders LIST_DIRECTORIES true RELATIVE "${KF_CLASSES_DIR}" "${KF_CLASSES_DIR}/*")
list(SORT kf_folders)
list(REVERSE kf_folders)
foreach(kf_folder IN LISTS kf_folders)
  if(IS_DIRECTORY "${KF_CLASSES_DIR}/${kf_folder}")
    file(GLOB kf_left "${KF_CLASSES_DIR}/${kf_folder}/*")
    if(NOT kf_left)
      file(REMOVE_RECURSE "${KF_CLASSES_DIR}/${kf_folder}")  # empty: nothing else goes
    endif()
  endif()
endforeach()
