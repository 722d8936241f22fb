#pragma once
/// \file runtime.hpp
/// \brief What every service main shares: the common command-line options, stop on SIGINT/SIGTERM,
/// logging set-up.
#include <atomic>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace mannequin::service {

/// Options every service accepts (the launcher passes --name, --publish, --connect).
struct CommonOptions {
  std::string config;                 ///< --config FILE (YAML)
  std::string name;                   ///< --name: Header.source and heartbeat name (default: the service)
  std::vector<std::string> publish;   ///< --publish ENDPOINT (repeatable): overrides the config's `publish`
  std::vector<std::string> connect;   ///< --connect ENDPOINT (repeatable): overrides the config's `connect`
  double duration = 0.0;              ///< --duration S: stop by itself after S seconds (0 = run until a signal)
  std::string log_level = "info";     ///< --log-level
  double heartbeat_period = 0.5;      ///< --heartbeat-period S
};

/// Adds the common options to a CLI11 app.
void addCommonOptions(CLI::App& app, CommonOptions& options, bool config_required);

/// Sets the spdlog level and a pattern without the date (the launcher prefixes and timestamps lines).
/// \throws std::invalid_argument for an unknown level.
void setupLogging(const std::string& level);

/// Installs SIGINT/SIGTERM handlers that set the returned flag (the one process-wide state a signal
/// handler needs). SIGPIPE is ignored.
const std::atomic<bool>& installStopSignals();

}  // namespace mannequin::service
