# add_present_subdirectories([PLANT_SIDE dir...]): adds every immediate subdirectory that has a
# CMakeLists.txt, in name order, so each component (and each tool or test suite) owns its own build
# file. The PLANT_SIDE ones need the simulated machine and are left out when EXC_FIRMWARE_ONLY is on.
function(add_present_subdirectories)
  cmake_parse_arguments(ARG "" "" "PLANT_SIDE" ${ARGN})
  file(GLOB children LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/*)
  list(SORT children)
  foreach(child ${children})
    if(EXC_FIRMWARE_ONLY AND child IN_LIST ARG_PLANT_SIDE)
      continue()
    endif()
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${child} AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${child}/CMakeLists.txt)
      add_subdirectory(${child})
    endif()
  endforeach()
endfunction()

include(/usr/lib/cmake/doctest/doctest.cmake OPTIONAL RESULT_VARIABLE _exc_doctest_cmake)
if(NOT _exc_doctest_cmake)
  find_file(_exc_doctest_cmake doctest.cmake PATHS ${doctest_DIR} REQUIRED)
  include(${_exc_doctest_cmake})
endif()

# exc_add_doctest(target SOURCES ... [LIBS ...] [ENV ...]): one doctest executable; each TEST_CASE
# becomes its own ctest test, named exactly as the case (names start with the component:
# "hal/codec rejects stale counter"), so `ctest -R ^hal` runs one area.
function(exc_add_doctest target)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;LIBS;ENV;PROPERTIES" ${ARGN})
  add_executable(${target} ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE doctest::doctest exc_test_support exc_allocation_counter ${ARG_LIBS})
  target_compile_definitions(${target} PRIVATE
    EXC_SOURCE_DIR="${EXC_SOURCE_DIR}" EXC_MACHINE_FILE="${EXC_MACHINE_FILE}"
    EXC_BINARY_DIR="${CMAKE_BINARY_DIR}")
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  # The address and thread sanitizers slow the code 2-15x: their builds give each case 3x the time.
  if(EXC_SANITIZE STREQUAL "address" OR EXC_SANITIZE STREQUAL "thread")
    math(EXPR ARG_TIMEOUT "${ARG_TIMEOUT} * 3")
  endif()
  # A case that reports SKIPPED (a peer library absent) shows as skipped in a user's build; in the test
  # build (CI) nothing may skip: without the property the case asserted nothing and the main fails it.
  set(_props TIMEOUT ${ARG_TIMEOUT})
  if(NOT EXC_TEST_BUILD)
    list(APPEND _props SKIP_REGULAR_EXPRESSION "SKIPPED:")
  endif()
  if(ARG_ENV)
    list(APPEND _props ENVIRONMENT "${ARG_ENV}")
  endif()
  list(APPEND _props ${ARG_PROPERTIES})
  doctest_discover_tests(${target} PROPERTIES ${_props})
endfunction()
