#pragma once
/// \file main.hpp
/// \brief What every executable's main shares: command-line parsing with the project's exit codes,
/// logging set-up, one catch around the body, stop signals.
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace mannequin::core {

/// Exit codes of every mannequin executable.
inline constexpr int kExitOk = 0;       ///< done (also --help)
inline constexpr int kExitFailure = 1;  ///< the body threw (bad input file, I/O, ...) or returned 1
inline constexpr int kExitUsage = 2;    ///< bad command line (message and usage on stderr)

/// Parses `app` from argc/argv, sets up logging (level info, see setupLogging), then runs `body`:
/// returns its code, or kExitFailure after logging `critical` with what() when it throws (never
/// terminates; a bad input file is such a failure). --help exits kExitOk, a bad command line
/// kExitUsage before the body runs; a CLI::ParseError thrown by the body (a check of how options
/// combine, e.g. CLI::ValidationError) is a bad command line too.
int runMain(CLI::App& app, int argc, char** argv, const std::function<int()>& body);
/// The same with the arguments as a vector (program name excluded), for a main that rewrites them.
int runMain(CLI::App& app, std::vector<std::string> args, const std::function<int()>& body);

/// Sets the spdlog level and a pattern without the date (the launcher prefixes and timestamps lines);
/// the default logger writes to stderr.
/// \throws std::invalid_argument for an unknown level.
void setupLogging(const std::string& level);

/// A CLI11 check accepting the spdlog level names (trace, debug, info, warn, error, critical, off).
CLI::Validator logLevelCheck();

/// Installs SIGINT/SIGTERM handlers that set the returned flag (the one process-wide state a signal
/// handler needs); SIGPIPE is ignored. Idempotent.
const std::atomic<bool>& installStopSignals();

}  // namespace mannequin::core
