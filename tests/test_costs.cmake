# Included by ctest after the Catch2 tests are discovered (TEST_INCLUDE_FILES, CMakeLists.txt).
# `ctest -j` starts the tests in descending COST when it has no timings of its own yet, as in a
# fresh build directory (CI): without these, the longest tests come in file order and start
# near the end, while the other cores wait. Each COST is the test's seconds under the
# sanitizers on 2 cores, where the order matters most; a rough figure is enough. ctest ignores a
# name that matches no test: a renamed test must be renamed here too, which the test "ctest: every
# test that test_costs.cmake orders exists" (check_test_costs.cmake) holds.
set(_floedem_slow_tests
  "cli: no heap allocation in the steady state of a packed field|70"
  "every shipped scenario loads|40"
  "pair cache: every step the same pairs as a fresh broad phase|40"
  "coloured_from picks the order per island: its bounds are the shorthand's two orders|25"
  "resume: a run killed mid-way and continued gives the uninterrupted run's file|24"
  "field: concentration within 0.005 of the target, no overlap, inside the domain|19")
foreach(_entry IN LISTS _floedem_slow_tests)
  string(REPLACE "|" ";" _parts "${_entry}")
  list(GET _parts 0 _name)
  list(GET _parts 1 _cost)
  set_tests_properties("${_name}" PROPERTIES COST ${_cost})
endforeach()
