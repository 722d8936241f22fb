#pragma once
// What every bench-* executable shares: shipped files (configs/, data/) found from any working
// directory with core::findData, and a main that turns any error into a message on stderr and exit
// code 2 — a benchmark never ends in std::terminate.
#include <benchmark/benchmark.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>
#include <initializer_list>
#include <memory>
#include <string>

#include "mannequin/core/paths.hpp"

namespace mannequin::bench {

/// A shipped file, e.g. "configs/mannequins/male_50th.yaml", as an existing path.
/// \throws core::ConfigError "PATH: not found (looked in: ...)".
inline std::string dataFile(const std::string& relative) { return core::findData(relative); }

/// Checks that every listed shipped file exists before any benchmark runs. \throws like dataFile.
inline void requireData(std::initializer_list<const char*> relative) {
  for (const char* r : relative) dataFile(r);
}

/// Runs body(); an exception is printed as "NAME: error: WHAT" and gives exit code 2.
template <class Body>
int guarded(const char* name, Body&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
  } catch (...) {
    std::fprintf(stderr, "%s: error: unknown exception\n", name);
  }
  return 2;
}

/// Google Benchmark's main body: 1 on an unknown flag, 0 after the run. Standard output carries the report
/// only (--benchmark_format=json is read by tools/perf-report): what the code under test logs (spdlog's
/// default logger, e.g. a service run in-process) goes to standard error.
inline int runSpecified(int argc, char** argv, benchmark::BenchmarkReporter* reporter = nullptr) {
  spdlog::set_default_logger(
      std::make_shared<spdlog::logger>("", std::make_shared<spdlog::sinks::stderr_color_sink_mt>()));
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (reporter != nullptr) {
    benchmark::RunSpecifiedBenchmarks(reporter);
  } else {
    benchmark::RunSpecifiedBenchmarks();
  }
  benchmark::Shutdown();
  return 0;
}

}  // namespace mannequin::bench

/// main() of a bench: checks the listed shipped files, runs the benchmarks, exit 2 on any error.
#define MANNEQUIN_BENCHMARK_MAIN(NAME, ...)                \
  int main(int argc, char** argv) {                        \
    return mannequin::bench::guarded(NAME, [&] {           \
      mannequin::bench::requireData({__VA_ARGS__});        \
      return mannequin::bench::runSpecified(argc, argv);   \
    });                                                    \
  }
