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
if(MANNEQUIN_SANITIZE)
  target_compile_options(mannequin_options INTERFACE -fsanitize=${MANNEQUIN_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(mannequin_options INTERFACE -fsanitize=${MANNEQUIN_SANITIZE})
endif()
# A checking build: EIGEN_RUNTIME_NO_MALLOC lets a test forbid Eigen heap allocations in a hot loop
# (Eigen::internal::set_is_malloc_allowed(false), tests/common/no_eigen_malloc.hpp), and asserts stay on
# (-UNDEBUG, also in Release) so the forbidden allocation fails eigen_assert wherever it happens.
if(MANNEQUIN_CHECK_RUNTIME_MALLOC)
  target_compile_definitions(mannequin_options INTERFACE EIGEN_RUNTIME_NO_MALLOC)
  target_compile_options(mannequin_options INTERFACE -UNDEBUG)
endif()

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

# mannequin_add_test(<name> SOURCES ... LIBS ... LABELS ...)
# One GoogleTest executable; each test case becomes a ctest test carrying LABELS.
function(mannequin_add_test name)
  # RUN_SERIAL: no other test runs beside this one's tests (tests that start many processes and whose
  # timing claims a starved host would break)
  cmake_parse_arguments(ARG "RUN_SERIAL" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} mannequin_options GTest::gtest GTest::gtest_main)
  # The test code itself is compiled at -O1 in Release (the libraries it tests stay at -O3): GoogleTest and
  # Eigen in test sources take a large share of the build at -O3, for harness code that does little work.
  target_compile_options(${name} PRIVATE $<$<CONFIG:Release>:-O1>)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin/tests)
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
  if(nlabels GREATER 1)
    set(script ${CMAKE_CURRENT_BINARY_DIR}/${name}_labels.cmake)
    file(WRITE ${script} "foreach(t IN LISTS ${name}_TESTS)\n  set_tests_properties(\"\${t}\" PROPERTIES LABELS \"${ARG_LABELS}\")\nendforeach()\n")
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
  # a tool's own sources (command line, file formats, reports) at -O1 in Release: its numerical work is
  # in the libraries it links, which stay at -O3
  target_compile_options(mannequin-${tool} PRIVATE $<$<CONFIG:Release>:-O1>)
endfunction()
