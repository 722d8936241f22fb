#pragma once
// Child processes in the tests: fork/exec with the output to a log, waits with a deadline that fail
// loudly, and signals only through the checked core::signalProcess (a pid ≤ 0 is never signalled).
// Link mannequin::core.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "mannequin/core/process.hpp"

namespace mannequin::testutil {

/// fork + execv(argv[0]) with stdout and stderr appended to `log` and stdin from /dev/null. Returns
/// the pid, or -1 (with a test failure naming the command) when fork failed; 127 is the child's exit
/// code when execv failed.
inline pid_t spawnProcess(const std::vector<std::string>& argv, const std::string& log) {
  std::vector<char*> a;
  for (const std::string& s : argv) a.push_back(const_cast<char*>(s.c_str()));
  a.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND, 0644);
    const int in = ::open("/dev/null", O_RDONLY);
    if (fd < 0 || in < 0) ::_exit(126);
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
    ::dup2(in, STDIN_FILENO);
    ::execv(a[0], a.data());
    ::_exit(127);
  }
  if (pid < 0) ADD_FAILURE() << "fork failed for " << argv[0] << ": " << std::strerror(errno);
  return pid;
}

/// The exit code of `status` (128 + signal when killed by one).
inline int exitCode(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status); }

/// Waits up to `timeout` for the child `pid` to exit; its exit code, or nullopt when it is still running
/// at the deadline (or pid ≤ 0, or not our child).
inline std::optional<int> waitExitWithin(pid_t pid, std::chrono::milliseconds timeout) {
  if (pid <= 0) return std::nullopt;
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return exitCode(status);
    if (r < 0 && errno != EINTR) return std::nullopt;
    if (std::chrono::steady_clock::now() >= until) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

/// Kills (SIGKILL, checked pid) and reaps a child that overstayed; for the failure paths.
inline void killAndReap(pid_t pid) {
  if (core::signalProcess(pid, SIGKILL) == core::SignalResult::kSent) ::waitpid(pid, nullptr, 0);
}

/// Waits up to `timeout` for `pid` to exit by itself; on the deadline the test fails naming `what`,
/// the child is killed and -1 returned.
inline int waitExit(pid_t pid, const std::string& what, std::chrono::milliseconds timeout) {
  if (pid <= 0) {
    ADD_FAILURE() << what << ": no process to wait for (pid " << pid << ")";
    return -1;
  }
  if (const auto code = waitExitWithin(pid, timeout)) return *code;
  ADD_FAILURE() << what << " (pid " << pid << ") did not exit within " << timeout.count() << " ms";
  killAndReap(pid);
  return -1;
}

/// SIGTERM to `pid` (checked: a pid ≤ 0 is refused and fails the test), then waitExit.
inline int stopAndWait(pid_t pid, const std::string& what, std::chrono::milliseconds timeout) {
  if (core::signalProcess(pid, SIGTERM) == core::SignalResult::kRefused) {
    ADD_FAILURE() << what << ": refused to signal pid " << pid;
    return -1;
  }
  return waitExit(pid, what + " after SIGTERM", timeout);
}

/// A process of the test, started with its output in a log; killed (checked pid) and reaped if the test
/// leaves before it was waited for (a failed ASSERT), so no process outlives the test.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::string& log) : what_(argv.at(0)) { pid_ = spawnProcess(argv, log); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (pid_ > 0) killAndReap(pid_);
  }
  bool started() const { return pid_ > 0; }
  /// Waits for it to exit by itself: its exit code (-1 and a test failure past the deadline).
  int wait(std::chrono::milliseconds timeout) { return done(waitExit(pid_, what_, timeout)); }
  /// SIGTERM, then waits: its exit code (-1 and a test failure past the deadline).
  int stop(std::chrono::milliseconds timeout) { return done(stopAndWait(pid_, what_, timeout)); }

 private:
  int done(int code) {
    pid_ = -1;
    return code;
  }
  std::string what_;
  pid_t pid_ = -1;
};

}  // namespace mannequin::testutil
