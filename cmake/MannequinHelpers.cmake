# Helpers shared by every target of the project.

# Compile options every project target gets (warnings, sanitizers).
add_library(mannequin_options INTERFACE)
target_compile_options(mannequin_options INTERFACE -Wall -Wextra -Wpedantic)
# In a unity batch every source is an included file, so GCC takes a class of a source's anonymous
# namespace used by another of its classes for a header's (-Wsubobject-linkage); it is not one.
if(CMAKE_UNITY_BUILD AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(mannequin_options INTERFACE -Wno-subobject-linkage)
endif()
if(MANNEQUIN_WERROR)
  target_compile_options(mannequin_options INTERFACE -Werror)
endif()
# The test executables' own code (property MANNEQUIN_TEST_CODE) gets MANNEQUIN_SANITIZE_TEST_CODE, the
# rest MANNEQUIN_SANITIZE; every executable links all of MANNEQUIN_SANITIZE's runtimes.
if(MANNEQUIN_SANITIZE)
  if(NOT DEFINED MANNEQUIN_SANITIZE_TEST_CODE OR MANNEQUIN_SANITIZE_TEST_CODE STREQUAL "")
    set(MANNEQUIN_SANITIZE_TEST_CODE ${MANNEQUIN_SANITIZE})
  endif()
  string(REPLACE "," "$<COMMA>" test_code_sanitizers "${MANNEQUIN_SANITIZE_TEST_CODE}")
  string(REPLACE "," "$<COMMA>" sanitizers "${MANNEQUIN_SANITIZE}")
  target_compile_options(mannequin_options INTERFACE
    $<IF:$<BOOL:$<TARGET_PROPERTY:MANNEQUIN_TEST_CODE>>,-fsanitize=${test_code_sanitizers},-fsanitize=${sanitizers}>
    -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(mannequin_options INTERFACE -fsanitize=${MANNEQUIN_SANITIZE})
endif()
# A checking build: EIGEN_RUNTIME_NO_MALLOC lets a test forbid Eigen heap allocations in a hot loop
# (Eigen::internal::set_is_malloc_allowed(false), tests/common/no_eigen_malloc.hpp), and asserts stay on
# (-UNDEBUG, also in Release) so the forbidden allocation fails eigen_assert wherever it happens.
if(MANNEQUIN_CHECK_RUNTIME_MALLOC)
  target_compile_definitions(mannequin_options INTERFACE EIGEN_RUNTIME_NO_MALLOC)
  target_compile_options(mannequin_options INTERFACE -UNDEBUG)
endif()

# mannequin_use_pch(<target> test|tool)
# The harness code (test executables: kind `test`; tools and service mains: kind `tool`) is compiled at -O1
# (MANNEQUIN_TEST_CODE_FLAGS), and each of its sources parses the Eigen, GoogleTest, CLI11, spdlog,
# yaml-cpp and protobuf headers again. With MANNEQUIN_PCH those headers
# (cmake/pch/<kind>.hpp) are parsed once per build tree, by the target mannequin_pch_<kind>, and every
# harness target of that kind reuses the result (REUSE_FROM). A precompiled header is only valid with the
# flags and definitions it was built with, so the host gets the harness code's flags and the consumers the
# host's third-party dependencies (mannequin_pch_<kind>_deps); GCC warns of a header it cannot use
# (-Winvalid-pch, an error under MANNEQUIN_WERROR), so a flag added to one side only fails the build.
function(mannequin_use_pch target kind)
  if(NOT MANNEQUIN_PCH)
    return()
  endif()
  set(host mannequin_pch_${kind})
  if(NOT TARGET ${host})
    add_library(${host}_deps INTERFACE)
    target_link_libraries(${host}_deps INTERFACE Eigen3::Eigen spdlog::spdlog yaml-cpp)
    if(kind STREQUAL "test")
      target_link_libraries(${host}_deps INTERFACE GTest::gtest)
    elseif(kind STREQUAL "tool")
      target_link_libraries(${host}_deps INTERFACE CLI11::CLI11)
    else()
      message(FATAL_ERROR "mannequin_use_pch(${target} ${kind}): the kind is test or tool")
    endif()
    add_executable(${host} EXCLUDE_FROM_ALL ${PROJECT_SOURCE_DIR}/cmake/pch/host.cpp)
    target_link_libraries(${host} PRIVATE ${host}_deps mannequin_options)
    target_compile_options(${host} PRIVATE ${MANNEQUIN_TEST_CODE_FLAGS})
    target_precompile_headers(${host} PRIVATE ${PROJECT_SOURCE_DIR}/cmake/pch/${kind}.hpp)
    # not one of build/bin's executables (each of those is a service, tool or benchmark with --help)
    set_target_properties(${host} PROPERTIES UNITY_BUILD OFF RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/pch)
    if(kind STREQUAL "test")
      set_target_properties(${host} PROPERTIES MANNEQUIN_TEST_CODE ON)
    endif()
  endif()
  target_link_libraries(${target} PRIVATE ${host}_deps)
  target_precompile_headers(${target} REUSE_FROM ${host})
endfunction()

# mannequin_add_library(<name> SOURCES ... [DEPS ...] [PRIVATE_DEPS ...])
# Creates target mannequin_<name> (alias mannequin::<name>) with headers in
# libs/<name>/include/mannequin/<name>/.
function(mannequin_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(mannequin_${name} STATIC ${ARG_SOURCES})
  add_library(mannequin::${name} ALIAS mannequin_${name})
  target_include_directories(mannequin_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(mannequin_${name} PUBLIC ${ARG_DEPS} mannequin_options PRIVATE ${ARG_PRIVATE_DEPS})
endfunction()

# mannequin_add_test(<name> SOURCES ... [LIBS ...] LABELS ... [TOOLS ...] [SYSTEM] [RUN_SERIAL] [TIMEOUT s])
# One GoogleTest executable; each test case becomes a ctest test carrying LABELS.
# A test of a library area (MANNEQUIN_LIBRARY_TEST_AREAS, tests/CMakeLists.txt) is a library test: it runs
# in-process, and tools/test runs it under ASan+UBSan. TOOLS names the project's executables it runs as
# processes (built before it; MANNEQUIN_BIN_DIR is their directory): such a test, like one marked SYSTEM and
# every test outside the library areas, is a system test. MANNEQUIN_TESTS says which kinds are built; the
# executable of a kind not built is not created (`if(TARGET ...)` guards what follows a call).
function(mannequin_add_test name)
  # RUN_SERIAL: no other test runs beside this one's tests (tests that start many processes and whose
  # timing claims a starved host would break)
  # SLOW <Suite.Name ...>: test cases that take tens of seconds; ctest starts them first (COST), so that on a
  # fresh tree (no timings of a previous run yet) a long one does not start last and run alone
  cmake_parse_arguments(ARG "RUN_SERIAL;SYSTEM" "TIMEOUT" "SOURCES;LIBS;LABELS;TOOLS;SLOW" ${ARGN})
  get_filename_component(area ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  set(kind system)
  if(area IN_LIST MANNEQUIN_LIBRARY_TEST_AREAS AND NOT ARG_SYSTEM AND NOT ARG_TOOLS)
    set(kind library)
  endif()
  if((MANNEQUIN_TESTS STREQUAL "libraries" AND kind STREQUAL "system") OR
     (MANNEQUIN_TESTS STREQUAL "system" AND kind STREQUAL "library"))
    return()
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} mannequin_options mannequin_test_main)
  target_compile_options(${name} PRIVATE ${MANNEQUIN_TEST_CODE_FLAGS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin/tests
                                           MANNEQUIN_TEST_CODE ON)
  mannequin_use_pch(${name} test)
  add_dependencies(all-tests ${name})
  foreach(tool ${ARG_TOOLS})
    if(TARGET ${tool})
      add_dependencies(${name} ${tool})
    endif()
  endforeach()
  if(ARG_TOOLS)
    target_compile_definitions(${name} PRIVATE MANNEQUIN_BIN_DIR="${CMAKE_BINARY_DIR}/bin")
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  # gtest_discover_tests flattens its PROPERTIES: a list of labels would break the pairs (the second
  # label taken for a property name). The first label goes there; a script included after the
  # discovered tests (their names in ${name}_TESTS) sets them all.
  set(first_label "")
  if(ARG_LABELS)
    list(GET ARG_LABELS 0 first_label)
  endif()
  gtest_discover_tests(${name}
    DISCOVERY_MODE PRE_TEST
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES LABELS "${first_label}" TIMEOUT ${ARG_TIMEOUT} RUN_SERIAL ${ARG_RUN_SERIAL}
    ENVIRONMENT "MANNEQUIN_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
  list(LENGTH ARG_LABELS nlabels)
  if(nlabels GREATER 1 OR ARG_SLOW)
    set(script ${CMAKE_CURRENT_BINARY_DIR}/${name}_properties.cmake)
    set(text "")
    if(nlabels GREATER 1)
      string(APPEND text "foreach(t IN LISTS ${name}_TESTS)\n  set_tests_properties(\"\${t}\" PROPERTIES LABELS \"${ARG_LABELS}\")\nendforeach()\n")
    endif()
    foreach(t ${ARG_SLOW})
      string(APPEND text "list(FIND ${name}_TESTS \"${t}\" at)\nif(NOT at EQUAL -1)\n  set_tests_properties(\"${t}\" PROPERTIES COST 1000)\nendif()\n")
    endforeach()
    file(WRITE ${script} "${text}")
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${script})
  endif()
endfunction()

# mannequin_add_bench(<area> SOURCES ... LIBS ...) -> build/bin/bench-<area>
function(mannequin_add_bench area)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(bench-${area} ${ARG_SOURCES})
  target_link_libraries(bench-${area} PRIVATE ${ARG_LIBS} mannequin_options benchmark::benchmark)
endfunction()

# mannequin_add_tool(<tool> SOURCES ... LIBS ...) -> build/bin/mannequin-<tool>
function(mannequin_add_tool tool)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(mannequin-${tool} ${ARG_SOURCES})
  target_link_libraries(mannequin-${tool} PRIVATE ${ARG_LIBS} mannequin_options)
  # a tool's own sources (command line, file formats, reports) are harness code: its numerical work is in
  # the libraries it links, which keep the build type's flags
  target_compile_options(mannequin-${tool} PRIVATE ${MANNEQUIN_TEST_CODE_FLAGS})
  mannequin_use_pch(mannequin-${tool} tool)
endfunction()
