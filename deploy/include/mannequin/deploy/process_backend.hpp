#pragma once
/// \file process_backend.hpp
/// \brief How the supervisor starts, signals and reaps a service's process: the seam between the
/// supervision logic and where the processes run. `LocalProcessBackend` forks and execs on this host
/// (own process group, killed with the launcher through PR_SET_PDEATHSIG, stdout+stderr into a pipe);
/// a remote agent (a host of a multi-host deployment) would implement the same four calls.
#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace mannequin::deploy {

/// A started process: its pid (> 0) and the read end of its output pipe (non-blocking, −1: none).
struct Launched {
  pid_t pid = -1;
  int output_fd = -1;
};

/// A process that ended: its pid and wait status (WIFEXITED/WIFSIGNALED apply).
struct Ended {
  pid_t pid = -1;
  int status = 0;
};

class ProcessBackend {
 public:
  virtual ~ProcessBackend() = default;
  /// Starts argv[0] (a resolved executable) with argv. nullopt and `error` set when it could not be
  /// started at all (pipe or fork failed); an exec failure shows as the process exiting with 127.
  virtual std::optional<Launched> start(const std::vector<std::string>& argv, std::string& error) = 0;
  /// Sends `signal` to the process group of pid. nullptr when sent or when the process already ended
  /// (the next reap collects it); else why not. Never signals a pid ≤ 0.
  virtual const char* signalGroup(pid_t pid, int signal) = 0;
  /// Every process that ended since the last call (non-blocking).
  virtual void reap(std::vector<Ended>& ended) = 0;
};

/// fork/exec on this host.
class LocalProcessBackend final : public ProcessBackend {
 public:
  std::optional<Launched> start(const std::vector<std::string>& argv, std::string& error) override;
  const char* signalGroup(pid_t pid, int signal) override;
  void reap(std::vector<Ended>& ended) override;
};

/// "exit 3", "signal 9 (Killed)".
std::string describeExit(int status);

}  // namespace mannequin::deploy
