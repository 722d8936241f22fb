// The supervisor with real processes: start, heartbeats, prefixed output, restart with backoff,
// permanent failure, clean stop, no process left behind.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "mannequin/core/process.hpp"
#include "mannequin/deploy/supervisor.hpp"
#include "../common/tool_run.hpp"

using namespace mannequin::deploy;

namespace {

using mannequin::core::processGone;

// Polls cond() (on status() snapshots) until it holds or `timeout` passes; false on the deadline.
template <class Cond>
bool waitFor(Cond cond, std::chrono::seconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!cond()) {
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}
}  // namespace

TEST(Supervisor, RunsRestartsStopsAndLeavesNoProcess) {
  const mannequin::testutil::TempDir tmp("mq-deploy");  // removed after the test, however it ends
  const std::string dir = tmp.path().string();
  const Deployment d = parseDeployment(R"(name: test
heartbeat_timeout: 2
stop_timeout: 3
services:
  - name: mocap
    exec: mannequin-mocap
    args: [--config, configs/sim/mocap_synthetic.yaml, --heartbeat-period, "0.1"]
    publish: ipc://${RUN_DIR}/mocap
  - name: broken
    exec: mannequin-mocap
    args: [--config, /nonexistent/config.yaml]
    publish: ipc://${RUN_DIR}/broken
    restart: {max_restarts: 2, backoff_initial: 0.05, backoff_max: 0.1}
)",
                                       "test.yaml", dir);
  SupervisorOptions o;
  o.exec_dir = MANNEQUIN_BIN_DIR;
  o.duration = 0;  // until `stop`: set once what the test checks has happened (no fixed window)
  o.status_period = 0.5;
  char* buffer = nullptr;
  std::size_t size = 0;
  std::FILE* out = open_memstream(&buffer, &size);
  o.out = out;
  Supervisor sup(d, o);
  std::atomic<bool> stop{false}, timed_out{false};
  std::thread watcher([&] {
    // at least 1.5 s (status lines), 5 heartbeats of mocap and 'broken' failed for good; 60 s at most
    const auto start = std::chrono::steady_clock::now();
    for (;;) {
      const auto st = sup.status();
      const bool done = st.size() == 2 && st[0].heartbeats >= 5 && st[1].state == ServiceState::kFailed;
      const auto elapsed = std::chrono::steady_clock::now() - start;
      if (done && elapsed >= std::chrono::milliseconds(1500)) break;
      if (elapsed > std::chrono::seconds(60)) {
        timed_out = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    stop = true;
  });
  const int rc = sup.run(stop);
  watcher.join();
  std::fclose(out);
  ASSERT_FALSE(timed_out) << "within 60 s: mocap did not send 5 heartbeats or 'broken' did not fail permanently";
  const std::string text(buffer, size);
  free(buffer);

  EXPECT_EQ(rc, 1) << text;  // 'broken' failed permanently
  const auto st = sup.status();
  ASSERT_EQ(st.size(), 2u);
  EXPECT_EQ(st[0].state, ServiceState::kStopped);
  EXPECT_EQ(st[0].last_exit, "exit 0");
  EXPECT_TRUE(st[0].clean_exit);
  EXPECT_EQ(st[0].starts, 1);
  EXPECT_GE(st[0].heartbeats, 5u);
  ASSERT_TRUE(st[0].has_heartbeat);
  EXPECT_EQ(st[0].heartbeat.service(), "mocap");
  EXPECT_EQ(st[0].heartbeat.pid(), st[0].pids[0]);
  EXPECT_EQ(st[1].state, ServiceState::kFailed);
  EXPECT_EQ(st[1].starts, 3);  // first run + 2 restarts
  EXPECT_EQ(st[1].restarts, 2);
  EXPECT_EQ(st[1].last_exit, "exit 2");  // bad command line
  // output is prefixed by the service name, status lines are printed
  EXPECT_NE(text.find("mocap    | info mocap: synthetic trajectories"), std::string::npos) << text;
  EXPECT_NE(text.find("broken   | --config: File does not exist"), std::string::npos) << text;
  EXPECT_NE(text.find("status   | 1/2 up | mocap"), std::string::npos) << text;
  EXPECT_NE(text.find("broken exited (exit 2) after 2 restarts: failed permanently"), std::string::npos) << text;
  // no process left: all reaped (not zombies) and gone
  for (const auto& s : st)
    for (pid_t p : s.pids) {
      EXPECT_TRUE(processGone(p)) << s.name << " pid " << p;
      EXPECT_FALSE(std::filesystem::exists("/proc/" + std::to_string(p))) << p;
    }
  EXPECT_EQ(waitpid(-1, nullptr, WNOHANG), -1);  // no child of ours left at all
  const std::string json = sup.summaryJson();
  EXPECT_NE(json.find("\"name\": \"broken\", \"state\": \"failed\", \"starts\": 3"), std::string::npos) << json;
  EXPECT_NE(sup.summary().find("pub mocap.frame"), std::string::npos);
}

TEST(Supervisor, StopFlagEndsTheRunAndCrashedServicesAreRestarted) {
  const mannequin::testutil::TempDir tmp("mq-deploy");  // removed after the test, however it ends
  const std::string dir = tmp.path().string();
  // a service killed by a signal is restarted; the launcher's stop flag ends everything
  const Deployment d = parseDeployment(R"(name: test2
services:
  - name: mocap
    exec: mannequin-mocap
    args: [--config, configs/sim/mocap_synthetic.yaml, --heartbeat-period, "0.1"]
    publish: ipc://${RUN_DIR}/mocap
    restart: {backoff_initial: 0.05}
)",
                                       "test2.yaml", dir);
  SupervisorOptions o;
  o.exec_dir = MANNEQUIN_BIN_DIR;
  o.status_period = 0;
  std::FILE* out = std::fopen("/dev/null", "w");
  o.out = out;
  Supervisor sup(d, o);
  std::atomic<bool> stop{false};
  std::thread killer([&] {
    // wait for the first heartbeat, kill the service, wait for its second run, then stop (always: a
    // wait that times out fails the test and still ends the run)
    pid_t first = -1;
    const bool up = waitFor(
        [&] {
          const ServiceStatus s = sup.status()[0];
          first = s.pid;
          return s.heartbeats > 0 && s.pid > 0;
        },
        std::chrono::seconds(20));
    if (!up) {
      ADD_FAILURE() << "mocap sent no heartbeat within 20 s (pid " << first << ")";
    } else if (const auto r = mannequin::core::signalProcess(first, SIGKILL); r != mannequin::core::SignalResult::kSent) {
      ADD_FAILURE() << "SIGKILL to mocap pid " << first << " not sent (" << static_cast<int>(r) << ")";
    } else if (!waitFor(
                   [&] {
                     const ServiceStatus s = sup.status()[0];
                     return s.starts == 2 && s.state == ServiceState::kUp;
                   },
                   std::chrono::seconds(20))) {
      const ServiceStatus s = sup.status()[0];
      ADD_FAILURE() << "mocap not restarted and up within 20 s of its SIGKILL: starts " << s.starts << ", state "
                    << toString(s.state);
    }
    stop = true;
  });
  const int rc = sup.run(stop);
  killer.join();
  std::fclose(out);
  const ServiceStatus st = sup.status()[0];
  EXPECT_EQ(st.starts, 2);
  EXPECT_EQ(st.restarts, 1);
  EXPECT_FALSE(st.clean_exit);  // it was killed once
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(st.state, ServiceState::kStopped);
  EXPECT_EQ(st.last_exit, "exit 0");
  for (pid_t p : st.pids) EXPECT_TRUE(processGone(p));
}
