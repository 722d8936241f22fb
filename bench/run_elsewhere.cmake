# ctest helper: runs EXE (a bench-* executable) on the cases matching FILTER, with the shortest
# min time, from a fresh temporary directory outside the checkout and without MANNEQUIN_SOURCE_DIR.
# Fails unless it exits 0 and ran a case named EXPECT (so a filter matching nothing fails too).
# cmake -DNAME=bench-x -DEXE=path -DFILTER=regex -DEXPECT=text -P run_elsewhere.cmake
if(NOT EXISTS "${EXE}")
  message(FATAL_ERROR "${EXE}: not built (cmake --build <build> --target ${NAME})")
endif()
set(base "$ENV{TMPDIR}")
if(base STREQUAL "")
  set(base "/tmp")
endif()
string(RANDOM LENGTH 10 tag)
set(dir "${base}/mannequin-${NAME}-${tag}")
file(MAKE_DIRECTORY "${dir}")
unset(ENV{MANNEQUIN_SOURCE_DIR})
execute_process(
  COMMAND "${EXE}" "--benchmark_filter=${FILTER}" "--benchmark_min_time=0.001"
  WORKING_DIRECTORY "${dir}"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
  TIMEOUT 240)
file(REMOVE_RECURSE "${dir}")
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "${NAME} run from ${dir} (filter ${FILTER}): exit '${rc}' (expected 0)\nstdout:\n${out}\nstderr:\n${err}")
endif()
string(FIND "${out}" "${EXPECT}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${NAME} run from ${dir}: no case '${EXPECT}' in its output (filter ${FILTER})\nstdout:\n${out}\nstderr:\n${err}")
endif()
message(STATUS "${NAME} ran '${EXPECT}' from ${dir}: exit 0")
