#pragma once
/// \file process.hpp
/// \brief The one way this project signals a process: a checked pid, never ≤ 0.
///
/// kill(-1, sig) signals every process the caller may signal (as root: nearly all of them), kill(0, sig)
/// the caller's own process group, kill(-pgid) a group. A pid read from a status that says "not running"
/// is −1 or 0; passing it to kill() is the bug this header exists to prevent.
#include <sys/types.h>

namespace mannequin::core {

/// What signalProcess did.
enum class SignalResult {
  kSent,        ///< kill() returned 0
  kRefused,     ///< pid ≤ 0 (or the group target ≤ 1): nothing was sent
  kNoProcess,   ///< ESRCH: already gone
  kFailed,      ///< another errno (EPERM, EINVAL)
};

/// Whom to signal.
enum class SignalTarget {
  kProcess,  ///< the process `pid`
  kGroup,    ///< the process group whose id is `pid` (kill(-pid)); pid must be > 1
};

/// Sends `sig` to the process (or process group) `pid`. Refuses pid ≤ 0 — and pid ≤ 1 for a group — and
/// returns kRefused without calling kill(). Async-signal-safe (no logging, no allocation).
SignalResult signalProcess(pid_t pid, int sig, SignalTarget target = SignalTarget::kProcess) noexcept;

/// True when `pid` > 0 names no process any more (kill(pid, 0) fails with ESRCH). False for pid ≤ 0.
bool processGone(pid_t pid) noexcept;

}  // namespace mannequin::core
