#pragma once
/// \file supervisor.hpp
/// \brief Runs a deployment on this host: starts every service of this host (fork/exec, own process group, killed
/// with the launcher through PR_SET_PDEATHSIG), prefixes and forwards their output line by line,
/// follows their heartbeats, restarts a crashed service with exponential backoff, and stops everything
/// (SIGTERM in reverse start order, SIGKILL after the stop timeout, every child reaped). Every signal
/// goes through core::signalProcess (a pid ≤ 0 — a service not running — is never signalled).
/// Multi-host: only the services of SupervisorOptions::host are started; the heartbeats of every
/// service (the other hosts' too) are followed, so the status shows the whole room.
#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <mannequin/v1/health.pb.h>

#include "mannequin/deploy/deployment.hpp"

namespace mannequin::deploy {

enum class ServiceState { kStarting, kUp, kLate, kBackoff, kFinished, kFailed, kStopped };
const char* toString(ServiceState s);

struct ServiceStatus {
  std::string name;
  std::string host;               ///< multi-host: its host ("" single-host)
  bool local = true;              ///< started by this launcher (false: another host's, heartbeats only)
  ServiceState state = ServiceState::kStarting;
  pid_t pid = -1;                 ///< -1 while not running (not started, exited, in backoff)
  std::vector<pid_t> pids;        ///< every pid it ran as
  int starts = 0;
  int restarts = 0;
  std::string last_exit;          ///< "exit 0", "signal 11", "" while running
  bool clean_exit = true;         ///< every exit was 0 or the SIGTERM of the shutdown
  bool has_heartbeat = false;
  std::int64_t last_heartbeat_ns = 0;  ///< steady clock
  std::uint64_t heartbeats = 0;
  v1::Heartbeat heartbeat;        ///< the last one
};

struct SupervisorOptions {
  std::string exec_dir;            ///< where to look for executables first (the launcher's directory)
  std::FILE* out = stdout;         ///< prefixed service output, status lines, summary
  bool tty = false;                ///< redraw one live status line instead of printing status lines
  double status_period = 5.0;      ///< s between status lines (tty: redraw period is 0.25 s)
  double duration = 0.0;           ///< stop by itself after this many seconds (0 = until stop)
  std::string host;                ///< multi-host: the host this launcher runs (its services are started)
};

/// An executable of a deployment: a name with '/' as is, else found in `exec_dir`, then in PATH
/// (unchanged when nowhere: the exec fails and the child reports it).
std::string resolveExecutable(const std::string& exec, const std::string& exec_dir);

class Supervisor {
 public:
  /// \throws std::invalid_argument when a multi-host deployment is given no host or an unknown one,
  /// or a single-host deployment a host.
  Supervisor(Deployment deployment, SupervisorOptions options);
  ~Supervisor();
  /// Runs until `stop` becomes true (SIGINT/SIGTERM) or the duration elapses, then stops everything.
  /// Returns 0 when every service ran and stopped cleanly, 1 if one failed permanently or exited badly
  /// (the services of this host; another host's are only shown).
  int run(const std::atomic<bool>& stop);
  /// A copy of the status of every service, safe to call from any thread while run() works (a
  /// snapshot taken after each iteration of run()'s loop and at its end).
  std::vector<ServiceStatus> status() const;
  /// "3/3 up | mocap 120 Hz | sim 1000 Hz, world 60.0 Hz, late 0.2 ms | ..." (of status()).
  std::string statusLine() const;
  /// Multi-line summary printed at the end (of status()).
  std::string summary() const;
  /// The same as JSON.
  std::string summaryJson() const;
  /// Resolved executable of a service (exec_dir, then PATH; a name with '/' is used as is).
  std::string resolveExec(const std::string& exec) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Deployment deployment_;
  SupervisorOptions options_;
  std::vector<ServiceStatus> status_;     ///< run()'s working copy (only run()'s thread touches it)
  mutable std::mutex snapshot_mutex_;
  std::vector<ServiceStatus> snapshot_;   ///< what status() returns (guarded by snapshot_mutex_)
  void publishSnapshot();
  static std::string statusLineOf(const std::vector<ServiceStatus>& status);
};

}  // namespace mannequin::deploy
