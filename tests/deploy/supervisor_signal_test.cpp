// The supervisor never signals a pid ≤ 0 (kill(-1) is every process, kill(0) our own group, kill(-(-1))
// init): every kill() of this executable is recorded by an interposed kill() (forwarded to the kernel unless it
// names -1, 0 or 1), and the services are stopped in every state where their pid is -1 — finished, failed,
// never started (exec failed), waiting for a restart — next to one that ignores SIGTERM (SIGKILL path).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "mannequin/core/process.hpp"
#include "mannequin/deploy/supervisor.hpp"

namespace {
std::mutex kills_mutex;
std::vector<std::pair<pid_t, int>> kills;  // every kill(pid, sig) of this process
}  // namespace

// Interposes libc's kill for this executable (the static libraries linked into it, core::signalProcess
// included, resolve kill here); records the call and makes the real system call — except for the
// targets this test exists to catch (-1: every process, 0: our group, 1: init), which are recorded
// (the test fails) and not sent, so a regression cannot take the machine down.
extern "C" int kill(pid_t pid, int sig) noexcept {
  {
    std::lock_guard<std::mutex> lock(kills_mutex);
    kills.emplace_back(pid, sig);
  }
  if (pid >= -1 && pid <= 1) {
    errno = EPERM;
    return -1;
  }
  return static_cast<int>(::syscall(SYS_kill, pid, sig));
}

using namespace mannequin::deploy;

namespace {
std::vector<std::pair<pid_t, int>> recordedKills() {
  std::lock_guard<std::mutex> lock(kills_mutex);
  return kills;
}

std::filesystem::path tempDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto p = std::filesystem::temp_directory_path() / ("mq-signal-" + std::string(info->name()) + "-" + std::to_string(getpid()));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

std::string script(const std::filesystem::path& dir, const std::string& name, const std::string& body) {
  const auto p = dir / name;
  std::ofstream(p) << "#!/bin/sh\n" << body << "\n";
  std::filesystem::permissions(p, std::filesystem::perms::owner_all);
  return p.string();
}
}  // namespace

TEST(SupervisorSignals, TheInterposerSeesKill) {
  // the recorder works: a refused pid never reaches kill(), a checked one does
  const std::size_t before = recordedKills().size();
  EXPECT_EQ(mannequin::core::signalProcess(-1, SIGKILL), mannequin::core::SignalResult::kRefused);
  EXPECT_EQ(recordedKills().size(), before);
  EXPECT_EQ(mannequin::core::signalProcess(getpid(), 0), mannequin::core::SignalResult::kSent);
  ASSERT_EQ(recordedKills().size(), before + 1);
  EXPECT_EQ(recordedKills().back(), std::make_pair(getpid(), 0));
}

TEST(SupervisorSignals, StoppingServicesThatAreNotRunningSignalsNoPidBelowOne) {
  const auto dir = tempDir();
  const std::string done = script(dir, "done.sh", "exit 0");
  const std::string fails = script(dir, "fails.sh", "exit 3");
  const auto trapped = dir / "trapped";  // 'stubborn' ignores SIGTERM from now on
  const std::string stubborn = script(dir, "stubborn.sh", "trap '' TERM\ntouch '" + trapped.string() + "'\nexec sleep 60");
  const Deployment d = parseDeployment(
      "name: signals\nheartbeat_timeout: 30\nstop_timeout: 0.5\nservices:\n"
      "  - {name: done, exec: " + done + ", publish: 'ipc://${RUN_DIR}/done', restart: {policy: never}}\n"
      "  - {name: failed, exec: " + fails + ", publish: 'ipc://${RUN_DIR}/failed', restart: {max_restarts: 0}}\n"
      "  - {name: missing, exec: " + (dir / "no-such-program").string() + ", publish: 'ipc://${RUN_DIR}/missing', restart: {policy: never}}\n"
      "  - {name: backoff, exec: " + fails + ", publish: 'ipc://${RUN_DIR}/backoff', restart: {backoff_initial: 60}}\n"
      "  - {name: stubborn, exec: " + stubborn + ", publish: 'ipc://${RUN_DIR}/stubborn'}\n",
      "signals.yaml", (dir / "run").string());
  SupervisorOptions o;
  o.status_period = 0;
  std::FILE* out = std::fopen((dir / "launch.log").c_str(), "w");
  ASSERT_NE(out, nullptr);
  o.out = out;
  Supervisor sup(d, o);
  std::atomic<bool> stop{false};
  const std::size_t kills_before = recordedKills().size();
  std::thread stopper([&] {
    // stop once every service but 'stubborn' is in its not-running state (pid -1) and 'stubborn' runs
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    auto ready = [&] {
      const auto st = sup.status();
      return st[0].state == ServiceState::kFinished && st[1].state == ServiceState::kFailed &&
             st[2].state == ServiceState::kFailed && st[3].state == ServiceState::kBackoff && st[4].pid > 0 &&
             std::filesystem::exists(trapped);
    };
    while (!ready() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (!ready()) {
      std::string states;
      for (const auto& s : sup.status()) states += s.name + " " + toString(s.state) + " pid " + std::to_string(s.pid) + "; ";
      ADD_FAILURE() << "the services did not reach finished/failed/failed/restarting/running (SIGTERM ignored) within 30 s: "
                    << states;
    }
    stop = true;
  });
  const int rc = sup.run(stop);
  stopper.join();
  std::fclose(out);
  EXPECT_EQ(rc, 1);  // 'failed' failed, 'stubborn' was killed

  const auto st = sup.status();
  std::set<pid_t> started;
  for (const auto& s : st) started.insert(s.pids.begin(), s.pids.end());
  const auto all = recordedKills();
  const std::vector<std::pair<pid_t, int>> calls(all.begin() + static_cast<std::ptrdiff_t>(kills_before), all.end());
  // no kill() with a pid that is not a started service's process or process group
  for (const auto& [pid, sig] : calls) {
    EXPECT_GT(std::abs(pid), 1) << "kill(" << pid << ", " << sig << ")";
    EXPECT_TRUE(started.count(std::abs(pid)) == 1) << "kill(" << pid << ", " << sig << ") names no started service";
  }
  // only 'stubborn' was signalled, SIGTERM then SIGKILL, to its process group
  ASSERT_EQ(st[4].pids.size(), 1u);
  const pid_t group = -st[4].pids[0];
  EXPECT_EQ(calls, (std::vector<std::pair<pid_t, int>>{{group, SIGTERM}, {group, SIGKILL}}));
  EXPECT_EQ(st[4].state, ServiceState::kStopped);
  EXPECT_EQ(st[4].last_exit, "signal 9 (Killed)");
  EXPECT_FALSE(st[4].clean_exit);
  EXPECT_EQ(st[3].state, ServiceState::kStopped);  // stopped while waiting for its restart
  for (const auto& s : st) {
    EXPECT_EQ(s.pid, -1) << s.name;
    for (pid_t p : s.pids) EXPECT_TRUE(mannequin::core::processGone(p)) << s.name << " pid " << p;
  }
  EXPECT_EQ(waitpid(-1, nullptr, WNOHANG), -1);  // every child reaped
  std::filesystem::remove_all(dir);
}
