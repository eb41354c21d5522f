# Writes OUT, a header defining CAMPROJ_GIT_REVISION: the short commit of SOURCE_DIR's checkout,
# "+dirty" when tracked files differ from it, "unknown" without git. Run at every build (the
# camproj_git_revision target); the file is rewritten only when the text changes, so only
# main.cc recompiles, and only after a commit or a change of dirtiness.
execute_process(COMMAND git -C "${SOURCE_DIR}" rev-parse --short=12 HEAD
                OUTPUT_VARIABLE revision OUTPUT_STRIP_TRAILING_WHITESPACE
                RESULT_VARIABLE status ERROR_QUIET)
if(NOT status EQUAL 0 OR revision STREQUAL "")
  set(revision "unknown")
else()
  execute_process(COMMAND git -C "${SOURCE_DIR}" diff --quiet HEAD --
                  RESULT_VARIABLE dirty ERROR_QUIET)
  if(NOT dirty EQUAL 0)
    string(APPEND revision "+dirty")
  endif()
endif()
set(text "#define CAMPROJ_GIT_REVISION \"${revision}\"\n")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT "${old}" STREQUAL "${text}")
  file(WRITE "${OUT}" "${text}")
endif()
