#include "mannequin/deploy/process_backend.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "mannequin/core/process.hpp"

namespace mannequin::deploy {

std::string describeExit(int status) {
  if (WIFEXITED(status)) return fmt::format("exit {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return fmt::format("signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)));
  return "unknown";
}

std::optional<Launched> LocalProcessBackend::start(const std::vector<std::string>& argv_s, std::string& error) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    error = fmt::format("pipe failed: {}", std::strerror(errno));
    return std::nullopt;
  }
  std::vector<char*> argv;
  for (const auto& a : argv_s) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(126);  // the launcher died between fork and prctl
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGPIPE, SIG_DFL);
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    int devnull = open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, STDIN_FILENO);
    execv(argv_s[0].c_str(), argv.data());
    const std::string msg = fmt::format("cannot execute '{}': {}\n", argv_s[0], std::strerror(errno));
    (void)!write(STDERR_FILENO, msg.data(), msg.size());
    _exit(127);
  }
  close(fds[1]);
  if (pid < 0) {
    close(fds[0]);
    error = fmt::format("fork failed: {}", std::strerror(errno));
    return std::nullopt;
  }
  setpgid(pid, pid);
  fcntl(fds[0], F_SETFL, O_NONBLOCK);
  return Launched{pid, fds[0]};
}

// The process group of a service (it is its group leader, setpgid in start). The check that a pid ≤ 0
// (a service not running) is never signalled is core::signalProcess's; kNoProcess (it exited since the
// last reap) is fine, the next reap collects it.
const char* LocalProcessBackend::signalGroup(pid_t pid, int sig) {
  switch (core::signalProcess(pid, sig, core::SignalTarget::kGroup)) {
    case core::SignalResult::kSent:
    case core::SignalResult::kNoProcess: return nullptr;
    case core::SignalResult::kRefused: return "refused (not a running process)";
    case core::SignalResult::kFailed: return std::strerror(errno);
  }
  return "?";
}

void LocalProcessBackend::reap(std::vector<Ended>& ended) {
  int status = 0;
  pid_t pid;
  while ((pid = waitpid(-1, &status, WNOHANG)) > 0) ended.push_back({pid, status});
}

}  // namespace mannequin::deploy
