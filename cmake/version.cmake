# Writes version.cpp with the current git commit; configure_file leaves it untouched (and so does
# not trigger a rebuild) when nothing changed.
execute_process(COMMAND git rev-parse --short=12 HEAD WORKING_DIRECTORY ${SOURCE_DIR}
                OUTPUT_VARIABLE LOAM_GIT_COMMIT OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT LOAM_GIT_COMMIT)
  set(LOAM_GIT_COMMIT "unknown")
else()
  execute_process(COMMAND git diff --quiet HEAD -- framework shapefunctions materials schemes plugins
                  WORKING_DIRECTORY ${SOURCE_DIR} RESULT_VARIABLE dirty ERROR_QUIET)
  if(dirty)
    set(LOAM_GIT_COMMIT "${LOAM_GIT_COMMIT}-dirty")
  endif()
endif()
set(PROJECT_VERSION ${VERSION})
configure_file(${SRC} ${DST} @ONLY)
