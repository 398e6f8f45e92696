# Writes OUT from IN with FLOEDEM_VERSION_STRING = PROJECT_VERSION+`git describe --always --dirty
# --tags` of SOURCE_DIR ("unknown" outside a checkout). Run at every build (native/CMakeLists.txt),
# so a run's output names the commit it was built from; configure_file leaves OUT untouched when
# the text is the same, so nothing recompiles unless the commit changed.
execute_process(COMMAND git describe --always --dirty --tags
  WORKING_DIRECTORY ${SOURCE_DIR}
  OUTPUT_VARIABLE FLOEDEM_GIT_DESCRIBE OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT FLOEDEM_GIT_DESCRIBE)
  set(FLOEDEM_GIT_DESCRIBE "unknown")
endif()
set(FLOEDEM_VERSION_STRING "${PROJECT_VERSION}+${FLOEDEM_GIT_DESCRIBE}")
configure_file(${IN} ${OUT} @ONLY)
