#include "mannequin/core/process.hpp"

#include <cerrno>
#include <csignal>

namespace mannequin::core {

SignalResult signalProcess(pid_t pid, int sig, SignalTarget target) noexcept {
  // never kill(0) (own group), kill(-1) (everything), kill(-1) via a group of 1 (init)
  if (pid <= 0) return SignalResult::kRefused;
  if (target == SignalTarget::kGroup && pid <= 1) return SignalResult::kRefused;
  const pid_t to = target == SignalTarget::kGroup ? -pid : pid;
  if (::kill(to, sig) == 0) return SignalResult::kSent;
  return errno == ESRCH ? SignalResult::kNoProcess : SignalResult::kFailed;
}

bool processGone(pid_t pid) noexcept {
  if (pid <= 0) return false;
  return ::kill(pid, 0) != 0 && errno == ESRCH;
}

}  // namespace mannequin::core
