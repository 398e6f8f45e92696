# `cmake --install`: the command, libfloedem as the CMake package floedem (target
# floedem::floedem, with a version file), its public headers, and what the command reads at
# run time (the report's scripts and the scenarios) under share/floedem. The command finds
# those relative to itself (app/python_script.cpp): bin/../share/floedem when installed, and
# in the build tree the same layout made of links to the sources (below).
include(CMakePackageConfigHelpers)
set(FLOEDEM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/floedem)

install(TARGETS floedem_lib EXPORT floedemTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS floedem RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/floedem DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.hpp")
install(EXPORT floedemTargets NAMESPACE floedem:: DESTINATION ${FLOEDEM_CMAKE_DIR})
set(FLOEDEM_ENGINE_NAMES native)
foreach(_engine IN ITEMS BOX2D BULLET MUJOCO ODE)
  if(FLOEDEM_WITH_${_engine})
    string(TOLOWER ${_engine} _lower)
    list(APPEND FLOEDEM_ENGINE_NAMES ${_lower})
  endif()
endforeach()
set(FLOEDEM_DATA_DIR ${CMAKE_INSTALL_DATADIR}/floedem)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/floedemConfig.cmake.in
  ${PROJECT_BINARY_DIR}/floedemConfig.cmake INSTALL_DESTINATION ${FLOEDEM_CMAKE_DIR} PATH_VARS FLOEDEM_DATA_DIR)
# Releases before 1.0 break their interface at every minor version (SameMinorVersion).
write_basic_package_version_file(${PROJECT_BINARY_DIR}/floedemConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/floedemConfig.cmake ${PROJECT_BINARY_DIR}/floedemConfigVersion.cmake
  DESTINATION ${FLOEDEM_CMAKE_DIR})

install(DIRECTORY ${PROJECT_SOURCE_DIR}/reports/ DESTINATION ${FLOEDEM_DATA_DIR}/reports
  FILES_MATCHING PATTERN "*.py" PATTERN "observations_verdicts_*.json" PATTERN "latest" EXCLUDE PATTERN "bench" EXCLUDE
  PATTERN "threads-*" EXCLUDE PATTERN "anchors" EXCLUDE PATTERN "tests" EXCLUDE PATTERN "__pycache__" EXCLUDE)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenarios/ DESTINATION ${FLOEDEM_DATA_DIR}/scenarios)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/profiles/ DESTINATION ${FLOEDEM_DATA_DIR}/profiles)
# The hindcast example: the report's hindcast section runs it as a user would.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/hindcast DESTINATION ${FLOEDEM_DATA_DIR}/examples
  FILES_MATCHING PATTERN "*.py" PATTERN "*.toml")
# The Python package: beside the command (which runs `python3 -m floedem` from there), with its
# pyproject.toml (pip install PREFIX/share/floedem/python), and where the Python that found
# numpy and h5py looks for packages of this prefix (cmake/python_site.py), so that
# `python3 -c "import floedem"` works after the install.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/python/ DESTINATION ${FLOEDEM_DATA_DIR}/python
  PATTERN "__pycache__" EXCLUDE PATTERN "tests" EXCLUDE PATTERN "*.egg-info" EXCLUDE)
if(FLOEDEM_PYTHON)
  install(CODE "
    execute_process(COMMAND ${FLOEDEM_PYTHON} ${PROJECT_SOURCE_DIR}/cmake/python_site.py \"\${CMAKE_INSTALL_PREFIX}\"
      OUTPUT_VARIABLE _site OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _rc)
    if(NOT _rc EQUAL 0)
      message(FATAL_ERROR \"floedem: cannot tell where Python looks for packages under \${CMAKE_INSTALL_PREFIX}\")
    endif()
    file(INSTALL ${PROJECT_SOURCE_DIR}/python/floedem DESTINATION \"\${_site}\" PATTERN __pycache__ EXCLUDE)
    message(STATUS \"floedem: Python package in \${_site}\")")
endif()

# The build tree's share/floedem: links to the sources, so that an edited script is the one run.
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/share/floedem)
foreach(_dir IN ITEMS reports scenarios python examples)
  file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${_dir} ${PROJECT_BINARY_DIR}/share/floedem/${_dir} SYMBOLIC)
endforeach()
