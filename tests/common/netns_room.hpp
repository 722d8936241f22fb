#pragma once
// The netns room of the deploy and fault tests: three network namespaces ("hosts" mocap 10.77.0.1, sim
// 10.77.0.2, station 10.77.0.3) joined by veth pairs on a bridge in the sim's namespace (its ports
// to_mocap and to_station), processes started in them with `ip netns exec`, and what a test reads back
// (a file containing a text, the sim.world of a recording). Needs root; link mannequin::recording,
// mannequin::transport and mannequin::core. The Room guard removes its processes, namespaces and directory in every path.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "child_process.hpp"
#include "mannequin/core/process.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/transport/security.hpp"
#include "mannequin/v1/world.pb.h"

namespace mannequin::testutil::netns {

namespace fs = std::filesystem;

inline std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline std::string ipTool() {
  for (const char* p : {"/usr/sbin/ip", "/sbin/ip", "/usr/bin/ip", "/bin/ip"})
    if (::access(p, X_OK) == 0) return p;
  return {};
}

/// Runs `ip ARGS...` to completion (20 s at most); its exit code (-1: could not run it), output in `log`.
inline int ip(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv{ipTool()};
  argv.insert(argv.end(), args.begin(), args.end());
  const pid_t pid = spawnProcess(argv, log.string());
  if (pid <= 0) return -1;
  if (const auto code = waitExitWithin(pid, std::chrono::seconds(20))) return *code;
  killAndReap(pid);
  return -1;
}

/// The three namespaces and the processes started in them; the destructor stops the processes (SIGTERM,
/// SIGKILL after 10 s), deletes the namespaces (their veth ends and bridge go with them) and the test's
/// directory.
class Room {
 public:
  explicit Room(fs::path dir) : dir_(std::move(dir)), prefix_("mq" + std::to_string(getpid())) {}
  ~Room() {
    for (const pid_t pid : pids_) {
      if (pid <= 0) continue;
      if (core::signalProcess(pid, SIGTERM) == core::SignalResult::kSent && !waitExitWithin(pid, std::chrono::seconds(10)))
        killAndReap(pid);
    }
    for (const std::string& ns : created_) ip({"netns", "del", ns}, "/dev/null");  // dir_ may be gone
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  Room(const Room&) = delete;
  Room& operator=(const Room&) = delete;

  std::string ns(const std::string& host) const { return prefix_ + host; }
  /// Creates the namespaces and links: "" when done, else what failed (with the ip output).
  std::string build() {
    const fs::path log = dir_ / "ip.log";
    auto run = [&](const std::vector<std::string>& args) {
      if (ip(args, log) == 0) return std::string();
      std::string cmd = "ip";
      for (const auto& a : args) cmd += " " + a;
      return cmd + " failed: " + readFile(log);
    };
    for (const char* h : {"mocap", "sim", "station"}) {
      if (auto e = run({"netns", "add", ns(h)}); !e.empty()) return e;
      created_.push_back(ns(h));
      if (auto e = run({"-n", ns(h), "link", "set", "lo", "up"}); !e.empty()) return e;
    }
    // the sim's namespace is the switch: a bridge with the far ends of both veth pairs
    const std::vector<std::vector<std::string>> steps = {
        {"-n", ns("sim"), "link", "add", "br0", "type", "bridge"},
        {"link", "add", "eth0", "netns", ns("mocap"), "type", "veth", "peer", "name", "to_mocap", "netns", ns("sim")},
        {"link", "add", "eth0", "netns", ns("station"), "type", "veth", "peer", "name", "to_station", "netns", ns("sim")},
        {"-n", ns("sim"), "link", "set", "to_mocap", "master", "br0"},
        {"-n", ns("sim"), "link", "set", "to_station", "master", "br0"},
        {"-n", ns("mocap"), "addr", "add", "10.77.0.1/24", "dev", "eth0"},
        {"-n", ns("sim"), "addr", "add", "10.77.0.2/24", "dev", "br0"},
        {"-n", ns("station"), "addr", "add", "10.77.0.3/24", "dev", "eth0"},
        {"-n", ns("mocap"), "link", "set", "eth0", "up"},
        {"-n", ns("station"), "link", "set", "eth0", "up"},
        {"-n", ns("sim"), "link", "set", "to_mocap", "up"},
        {"-n", ns("sim"), "link", "set", "to_station", "up"},
        {"-n", ns("sim"), "link", "set", "br0", "up"},
    };
    for (const auto& s : steps)
      if (auto e = run(s); !e.empty()) return e;
    return {};
  }
  /// Starts argv inside the namespace of `host` (ip netns exec execs it: the pid is the program's).
  pid_t start(const std::string& host, const std::vector<std::string>& argv, const fs::path& log) {
    std::vector<std::string> full{ipTool(), "netns", "exec", ns(host)};
    full.insert(full.end(), argv.begin(), argv.end());
    const pid_t pid = spawnProcess(full, log.string());
    pids_.push_back(pid);
    return pid;
  }
  /// SIGTERM to a process started here and its exit code (-1: not running or no exit within 20 s).
  int stop(pid_t pid, const std::string& what) {
    if (pid <= 0) return -1;
    if (core::signalProcess(pid, SIGTERM) != core::SignalResult::kSent) return -1;
    const int code = waitExit(pid, what, std::chrono::seconds(20));
    std::erase(pids_, pid);
    return code;
  }
  int wait(pid_t pid, const std::string& what, std::chrono::seconds timeout) {
    const int code = waitExit(pid, what, timeout);
    std::erase(pids_, pid);
    return code;
  }

 private:
  fs::path dir_;
  std::string prefix_;
  std::vector<std::string> created_;
  std::vector<pid_t> pids_;
};

/// Polls `done` (e.g. a log file's content: a file has no event to wait on) every 50 ms until it holds or
/// the deadline; true when it holds.
template <class Done>
bool waitUntil(Done done, std::chrono::seconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

/// Until every file contains `text` or the deadline; true when they all do.
inline bool waitForText(const std::vector<fs::path>& files, const std::string& text, std::chrono::seconds timeout) {
  return waitUntil(
      [&] {
        for (const auto& f : files)
          if (readFile(f).find(text) == std::string::npos) return false;
        return true;
      },
      timeout);
}

inline std::vector<v1::WorldState> worldsIn(const fs::path& mcap) {
  std::vector<v1::WorldState> out;
  const recording::McapReader reader = recording::McapReader::open(mcap.string());
  recording::ReadFilter filter;
  filter.topics = {"sim.world"};
  recording::MessageCursor cursor = reader.messages(filter);
  recording::Message msg;
  while (cursor.next(msg)) {
    v1::WorldState ws;
    if (ws.ParseFromString(msg.data)) out.push_back(std::move(ws));
  }
  return out;
}

/// Every message of a recording, whatever its topic.
inline std::size_t messagesIn(const fs::path& mcap) {
  const recording::McapReader reader = recording::McapReader::open(mcap.string());
  recording::MessageCursor cursor = reader.messages({});
  recording::Message msg;
  std::size_t n = 0;
  while (cursor.next(msg)) ++n;
  return n;
}


/// A CURVE key pair NAME.key_secret (0600) and NAME.key in `dir` for each name.
inline void writeKeyPairs(const fs::path& dir, const std::vector<std::string>& names) {
  for (const std::string& n : names) {
    const auto k = transport::generateCurveKeyPair();
    transport::writeKeyFile((dir / (n + ".key_secret")).string(), k.secret_key, "secret", 0600);
    transport::writeKeyFile((dir / (n + ".key")).string(), k.public_key, "public", 0644);
  }
}

}  // namespace mannequin::testutil::netns
