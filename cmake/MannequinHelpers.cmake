# Helpers shared by every target of the project.

# Compile options every project target gets (warnings, sanitizers).
add_library(mannequin_options INTERFACE)
target_compile_options(mannequin_options INTERFACE -Wall -Wextra -Wpedantic)
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

# Precompiled headers (MANNEQUIN_PCH, see CMakeLists.txt). Eigen and the standard library headers take a few
# seconds of every TU's parse; they are compiled once into mannequin_pch_lib (static libraries, -fPIC) and,
# with GoogleTest, into mannequin_pch_test (test executables, -fPIE). Every other target takes its PCH from
# one of them (REUSE_FROM), which needs the same compile options and definitions: the pch targets link
# mannequin_options like the targets that reuse them; target-private -D's (MANNEQUIN_BIN_DIR, ...) do not
# appear in these headers, so GCC keeps the PCH valid. The fuzz build (clang, per-target sanitizer flags)
# builds without. The headers are only a speed-up: every source still includes what it uses, and a build
# with -DMANNEQUIN_PCH=OFF (the default with ccache) checks that.
set(MANNEQUIN_PCH_HEADERS
  <Eigen/Dense> <algorithm> <array> <cmath> <cstdint> <functional> <limits> <map> <memory> <optional>
  <stdexcept> <string> <string_view> <utility> <vector>)

function(_mannequin_pch_target kind)
  if(TARGET mannequin_pch_${kind})
    return()
  endif()
  set(src ${CMAKE_BINARY_DIR}/mannequin_pch_${kind}.cpp)
  if(NOT EXISTS ${src})
    file(WRITE ${src} "// compiles the precompiled header of mannequin_pch_${kind} (cmake/MannequinHelpers.cmake)\n")
  endif()
  if(kind STREQUAL "lib")
    add_library(mannequin_pch_lib STATIC ${src})
    target_link_libraries(mannequin_pch_lib PRIVATE Eigen3::Eigen mannequin_options)
    target_precompile_headers(mannequin_pch_lib PRIVATE ${MANNEQUIN_PCH_HEADERS})
  else()
    # an executable (gtest_main's main), so its PCH is compiled like the tests' sources (-fPIE)
    add_executable(mannequin_pch_test ${src})
    target_link_libraries(mannequin_pch_test PRIVATE Eigen3::Eigen mannequin_options GTest::gtest GTest::gtest_main)
    set_target_properties(mannequin_pch_test PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/pch)
    target_precompile_headers(mannequin_pch_test PRIVATE ${MANNEQUIN_PCH_HEADERS} <gtest/gtest.h>)
  endif()
endfunction()

# _mannequin_use_pch(<target> lib|test): the target reuses mannequin_pch_<kind>'s PCH.
function(_mannequin_use_pch target kind)
  if(NOT MANNEQUIN_PCH OR MANNEQUIN_BUILD_FUZZ)
    return()
  endif()
  _mannequin_pch_target(${kind})
  # the PCH's headers must be found by the reusing target as well (include paths, should GCC refuse the PCH)
  target_link_libraries(${target} PRIVATE Eigen3::Eigen)
  target_precompile_headers(${target} REUSE_FROM mannequin_pch_${kind})
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
  _mannequin_use_pch(mannequin_${name} lib)
endfunction()

# mannequin_add_test(<name> SOURCES ... LIBS ... LABELS ...)
# One GoogleTest executable; each test case becomes a ctest test carrying LABELS.
function(mannequin_add_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} mannequin_options GTest::gtest GTest::gtest_main)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin/tests)
  _mannequin_use_pch(${name} test)
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  gtest_discover_tests(${name}
    DISCOVERY_MODE PRE_TEST
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT}
    ENVIRONMENT "MANNEQUIN_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
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
endfunction()
