#pragma once
/// \file restart_policy.hpp
/// \brief What happens when a service exits (no processes here: unit-testable): finished or failed for
/// good, or restarted after an exponential backoff (backoff_initial, doubled up to backoff_max), the
/// restart count reset once the service had run `stable_after` seconds, at most `max_restarts`.
#include "mannequin/deploy/deployment.hpp"

namespace mannequin::deploy {

class RestartTracker {
 public:
  enum class Decision { kFinished, kFailed, kRestart, kFailedPermanently };
  explicit RestartTracker(const RestartOptions& options) : options_(options) {}
  /// A run that lasted `ran_s` seconds ended, cleanly (exit 0) or not.
  Decision onExit(bool clean, double ran_s);
  /// After kRestart: seconds to wait before starting again.
  double backoff() const { return backoff_; }
  /// Restarts since the last stable run (counted when the restart happens: call restarted()).
  int restarts() const { return restarts_; }
  void restarted() { ++restarts_; }

 private:
  RestartOptions options_;
  double backoff_ = 0;
  int restarts_ = 0;
};

}  // namespace mannequin::deploy
