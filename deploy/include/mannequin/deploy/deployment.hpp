#pragma once
/// \file deployment.hpp
/// \brief A deployment file (configs/deployments/*.yaml): which services run, with which arguments,
/// where each publishes (its bound endpoint) and whom it connects to, restart policy.
///
/// Every service is started as
///   EXEC --name NAME --publish ENDPOINT [--connect ENDPOINT_OF_X ...] ARGS...
/// with ${RUN_DIR} in endpoints and arguments replaced by the run directory (ipc sockets live there).
#include <string>
#include <vector>

namespace mannequin::deploy {

enum class RestartPolicy { kNever, kOnFailure, kAlways };

struct RestartOptions {
  RestartPolicy policy = RestartPolicy::kOnFailure;  ///< on-failure: restart unless it exited with 0
  int max_restarts = 5;          ///< more restarts than this → failed permanently
  double backoff_initial = 0.5;  ///< s before the first restart, doubled after each
  double backoff_max = 8.0;      ///< s
  double stable_after = 10.0;    ///< s of running that resets the backoff and the restart count
};

struct ServiceSpec {
  std::string name;
  std::string exec;                  ///< executable: a path, or a name looked up next to mannequin-launch, then in PATH
  std::vector<std::string> args;     ///< extra arguments (after the generated ones)
  std::string publish;               ///< endpoint it binds (expanded)
  std::vector<std::string> connect;  ///< names of the services it subscribes to
  RestartOptions restart;
  int line = 0;                      ///< line of its entry in the file
};

struct Deployment {
  std::string name;
  std::string source;          ///< file path
  std::string run_dir;         ///< expanded
  double heartbeat_timeout = 3.0;  ///< s without a heartbeat before a service is shown late
  double stop_timeout = 3.0;       ///< s between SIGTERM and SIGKILL at shutdown
  std::vector<ServiceSpec> services;  ///< start order (stopped in reverse)

  /// The endpoint of service `name`. \throws std::out_of_range.
  const std::string& endpointOf(const std::string& name) const;
  /// argv of service i (argv[0] = exec as written).
  std::vector<std::string> commandLine(std::size_t i) const;
};

/// Reads a deployment file. `run_dir` ("" = the file's `run_dir`, else /tmp/mannequin-<name>-<uid>)
/// replaces ${RUN_DIR}. \throws core::ConfigError "FILE:LINE: field '...': ..." (unknown keys,
/// duplicate names, a connect naming no service, a service without publish endpoint, bad numbers).
Deployment loadDeployment(const std::string& path, const std::string& run_dir = {});
Deployment parseDeployment(const std::string& yaml, const std::string& source, const std::string& run_dir = {});

/// Replaces every ${RUN_DIR} of `text`.
std::string expandRunDir(const std::string& text, const std::string& run_dir);

}  // namespace mannequin::deploy
