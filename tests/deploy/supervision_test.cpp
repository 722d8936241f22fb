// The supervisor's parts without processes (deploy/include/mannequin/deploy/restart_policy.hpp,
// heartbeat_monitor.hpp, status_printer.hpp): the restart decisions and backoff sequence, liveness from
// heartbeats, the launcher's output on a terminal and in a log; and the local process backend on /bin/sh.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "mannequin/deploy/heartbeat_monitor.hpp"
#include "mannequin/deploy/process_backend.hpp"
#include "mannequin/deploy/restart_policy.hpp"
#include "mannequin/deploy/status_printer.hpp"

using namespace mannequin::deploy;
using Decision = RestartTracker::Decision;

TEST(RestartTracker, OnFailureRestartsWithDoublingBackoffUpToTheMaxThenFailsPermanently) {
  RestartOptions o;
  o.policy = RestartPolicy::kOnFailure;
  o.max_restarts = 4;
  o.backoff_initial = 0.5;
  o.backoff_max = 1.5;
  o.stable_after = 10;
  RestartTracker r(o);
  const double expected[] = {0.5, 1.0, 1.5, 1.5};  // doubled, capped at backoff_max
  for (double b : expected) {
    ASSERT_EQ(r.onExit(false, 0.1), Decision::kRestart);
    EXPECT_DOUBLE_EQ(r.backoff(), b);
    r.restarted();
  }
  EXPECT_EQ(r.restarts(), 4);
  EXPECT_EQ(r.onExit(false, 0.1), Decision::kFailedPermanently);
}

TEST(RestartTracker, AStableRunResetsTheCountAndTheBackoff) {
  RestartOptions o;
  o.max_restarts = 2;
  o.backoff_initial = 0.5;
  o.stable_after = 10;
  RestartTracker r(o);
  ASSERT_EQ(r.onExit(false, 1), Decision::kRestart);
  r.restarted();
  ASSERT_EQ(r.onExit(false, 1), Decision::kRestart);
  EXPECT_DOUBLE_EQ(r.backoff(), 1.0);
  r.restarted();
  // it then ran 12 s: stable, the count and the backoff start again
  ASSERT_EQ(r.onExit(false, 12), Decision::kRestart);
  EXPECT_EQ(r.restarts(), 0);
  EXPECT_DOUBLE_EQ(r.backoff(), 0.5);
}

TEST(RestartTracker, PoliciesDecideOnTheExitStatus) {
  RestartOptions o;
  o.policy = RestartPolicy::kOnFailure;
  EXPECT_EQ(RestartTracker(o).onExit(true, 1), Decision::kFinished);
  o.policy = RestartPolicy::kNever;
  EXPECT_EQ(RestartTracker(o).onExit(false, 1), Decision::kFailed);
  EXPECT_EQ(RestartTracker(o).onExit(true, 1), Decision::kFinished);
  o.policy = RestartPolicy::kAlways;
  EXPECT_EQ(RestartTracker(o).onExit(true, 1), Decision::kRestart);
}

TEST(Liveness, UpWhileHeartbeatsAreFreshLateAfterTheTimeoutStartingBefore) {
  const std::int64_t s = 1'000'000'000;
  EXPECT_EQ(liveness(false, 0, 0, s / 2, 1.0), ServiceState::kStarting);
  EXPECT_EQ(liveness(false, 0, 0, 2 * s, 1.0), ServiceState::kLate);
  EXPECT_EQ(liveness(true, 3 * s, 0, 3 * s + s / 2, 1.0), ServiceState::kUp);
  EXPECT_EQ(liveness(true, 3 * s, 0, 5 * s, 1.0), ServiceState::kLate);
}

namespace {
std::string printed(bool tty, void (*write)(StatusPrinter&)) {
  char* buf = nullptr;
  std::size_t size = 0;
  std::FILE* f = open_memstream(&buf, &size);
  {
    StatusPrinter p(f, tty, 6);
    write(p);
  }
  std::fclose(f);
  std::string out(buf, size);
  std::free(buf);
  return out;
}
}  // namespace

TEST(StatusPrinter, ALogGetsStatusLinesATerminalOneRedrawnLine) {
  const auto body = [](StatusPrinter& p) {
    p.line("sim", "stepping");
    p.status("2/2 up");
    p.launcher("stopping");
  };
  EXPECT_EQ(printed(false, body), "sim    | stepping\nstatus | 2/2 up\nlaunch | stopping\n");
  // on a terminal the status line is drawn without a newline and erased before the next line
  EXPECT_EQ(printed(true, body), "sim    | stepping\n2/2 up\r\033[Klaunch | stopping\n");
}

TEST(LocalProcessBackend, StartsCapturesOutputSignalsTheGroupAndReaps) {
  LocalProcessBackend b;
  std::string error;
  auto sleeper = b.start({"/bin/sh", "-c", "echo ready; exec sleep 30"}, error);
  ASSERT_TRUE(sleeper.has_value()) << error;
  ASSERT_GT(sleeper->pid, 0);
  // its output through the pipe (non-blocking: poll with a deadline)
  std::string out;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  char buf[256];
  while (out.find("ready\n") == std::string::npos) {
    ASSERT_LT(std::chrono::steady_clock::now(), until) << "no output within 10 s: '" << out << "'";
    const ssize_t n = read(sleeper->output_fd, buf, sizeof buf);
    if (n > 0) out.append(buf, static_cast<std::size_t>(n));
    std::this_thread::yield();
  }
  EXPECT_EQ(b.signalGroup(sleeper->pid, SIGTERM), nullptr);
  std::vector<Ended> ended;
  while (ended.empty()) {
    ASSERT_LT(std::chrono::steady_clock::now(), until) << "not reaped within 10 s";
    b.reap(ended);
    std::this_thread::yield();
  }
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].pid, sleeper->pid);
  EXPECT_EQ(describeExit(ended[0].status), "signal 15 (Terminated)");
  close(sleeper->output_fd);
  // a pid ≤ 0 is never signalled
  EXPECT_NE(b.signalGroup(0, SIGTERM), nullptr);
  EXPECT_NE(b.signalGroup(-1, SIGKILL), nullptr);
  // a missing executable: the child reports it and exits 127
  auto missing = b.start({"/nonexistent/mannequin-nothing"}, error);
  ASSERT_TRUE(missing.has_value());
  ended.clear();
  while (ended.empty()) {
    ASSERT_LT(std::chrono::steady_clock::now(), until) << "not reaped within 10 s";
    b.reap(ended);
    std::this_thread::yield();
  }
  EXPECT_EQ(describeExit(ended[0].status), "exit 127");
  close(missing->output_fd);
}
