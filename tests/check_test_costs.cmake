# Every test that test_costs.cmake orders must exist: ctest applies a COST to a name that matches
# no test without a word, so a renamed test would silently lose its place at the head of the
# queue (and CI its two cores' overlap). Run as a test (tests/CMakeLists.txt):
#   cmake -DCTEST=<ctest> -DBUILD_DIR=<tests' build dir> -DCOSTS=<test_costs.cmake> -P this file
foreach(_var IN ITEMS CTEST BUILD_DIR COSTS)
  if(NOT DEFINED ${_var})
    message(FATAL_ERROR "check_test_costs.cmake: -D${_var}=... is required")
  endif()
endforeach()

# The names ctest knows, from its machine-readable listing (no parsing of the human one).
execute_process(COMMAND ${CTEST} -N --show-only=json-v1
  WORKING_DIRECTORY ${BUILD_DIR} OUTPUT_VARIABLE _json RESULT_VARIABLE _rc ERROR_VARIABLE _err)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "check_test_costs.cmake: `ctest -N` failed in ${BUILD_DIR}: ${_err}")
endif()
string(JSON _count LENGTH "${_json}" tests)
set(_known "")
math(EXPR _last "${_count} - 1")
foreach(_i RANGE ${_last})
  string(JSON _name GET "${_json}" tests ${_i} name)
  list(APPEND _known "${_name}")
endforeach()

# The names test_costs.cmake gives a COST to: read by running the file itself with
# set_tests_properties recording its first argument, so that the check sees exactly what ctest
# is given.
set(_costed "")
function(set_tests_properties _name)
  set(_costed "${_costed};${_name}" PARENT_SCOPE)
endfunction()
include(${COSTS})

set(_missing 0)
foreach(_name IN LISTS _costed)
  if(_name STREQUAL "")
    continue()
  endif()
  list(FIND _known "${_name}" _at)
  if(_at EQUAL -1)
    message(SEND_ERROR "${COSTS}: field 'COST': no test named \"${_name}\" (renamed? name it as ctest -N does)")
    math(EXPR _missing "${_missing} + 1")
  endif()
endforeach()
if(_missing EQUAL 0)
  list(REMOVE_ITEM _costed "")
  list(LENGTH _costed _n)
  message(STATUS "${_n} costed tests, each one of the ${_count} that ctest knows")
endif()
