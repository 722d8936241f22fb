// End to end on loopback: the launcher starts mocap (the shipped BVH capture), collision and sim from a
// test deployment (ipc endpoints in a temp dir); heartbeats of all three; the capture drives the
// mannequin; sim.world arrives at the configured rate; garbage on every topic the services read is
// counted and does not stop them; SIGTERM to the launcher stops everything cleanly; no process is left.
// Every phase waits on a condition with a deadline (sim.world flowing, the fuzzer's subscribers joined,
// the "3/3 up" status line, the launcher's exit) and fails naming it.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <random>
#include <sstream>
#include <thread>

#include "../common/child_process.hpp"
#include "mannequin/core/process.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/security.hpp"
#include "mannequin/transport/subscriber.hpp"

using namespace mannequin;

namespace {
std::string readFile(const std::string& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A tcp port free on this host now (bound to port 0 and released), for a test deployment.
int freePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  socklen_t len = sizeof(a);
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    if (fd >= 0) ::close(fd);
    return 0;
  }
  ::close(fd);
  return ntohs(a.sin_port);
}
}  // namespace

// The same multi-host deployment run by two launchers (hosts a and b, both this machine's loopback):
// each starts only its host's service (binding tcp://*:PORT) and shows the other's from its heartbeats
// ("2/2 up"); the other's is in its summary as on host b, not started here (no pid, no start). CURVE:
// the launchers' monitors are CURVE clients, so "up" means the services took the keys the launcher
// gave them; a missing key file is refused before anything starts (exit 2, FILE:LINE).
TEST(EndToEnd, TwoLaunchersOfOneMultiHostDeploymentEachStartTheirShareAndSeeTheWholeRoom) {
  const auto dir = std::filesystem::temp_directory_path() / ("mq-e2e-hosts-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const int port_a = freePort(), port_b = freePort();
  ASSERT_GT(port_a, 0);
  ASSERT_GT(port_b, 0);
  ASSERT_NE(port_a, port_b);
  const std::string deployment = (dir / "room.yaml").string();
  {
    std::ofstream out(deployment);
    out << "name: room\nheartbeat_timeout: 2.0\nhosts:\n  - {name: a, address: 127.0.0.1}\n  - {name: b, address: 127.0.0.1}\n"
           "security: {key_dir: keys}\n"
           "services:\n"
           "  - name: mocap_a\n    host: a\n    exec: mannequin-mocap\n"
           "    args: [--config, configs/sim/mocap_synthetic.yaml, --heartbeat-period, '0.2']\n"
           "    publish: tcp://*:" << port_a << "\n"
           "  - name: mocap_b\n    host: b\n    exec: mannequin-mocap\n"
           "    args: [--config, configs/sim/mocap_synthetic.yaml, --heartbeat-period, '0.2']\n"
           "    publish: tcp://0.0.0.0:" << port_b << "\n";
  }
  // keys: none yet → refused before anything starts
  const std::string check_log = (dir / "check.log").string();
  const pid_t check = testutil::spawnProcess({std::string(MANNEQUIN_BIN_DIR) + "/mannequin-launch", deployment, "--host", "a", "--check"},
                                             check_log);
  EXPECT_EQ(testutil::waitExit(check, "mannequin-launch --check without keys", std::chrono::seconds(20)), 2) << readFile(check_log);
  EXPECT_NE(readFile(check_log).find(deployment + ":6: field 'security.key_dir': " + (dir / "keys").string()), std::string::npos)
      << readFile(check_log);
  std::filesystem::create_directories(dir / "keys");
  for (const char* n : {"mocap_a", "mocap_b", "launch.a", "launch.b"}) {
    const auto k = transport::generateCurveKeyPair();
    transport::writeKeyFile((dir / "keys" / (std::string(n) + ".key_secret")).string(), k.secret_key, "secret", 0600);
    transport::writeKeyFile((dir / "keys" / (std::string(n) + ".key")).string(), k.public_key, "public", 0644);
  }
  struct Launcher {
    std::string host, log, summary;
    pid_t pid = -1;
  };
  std::vector<Launcher> launchers;
  for (const char* host : {"a", "b"}) {
    Launcher l{host, (dir / (std::string(host) + ".log")).string(), (dir / (std::string(host) + ".json")).string()};
    l.pid = testutil::spawnProcess({std::string(MANNEQUIN_BIN_DIR) + "/mannequin-launch", deployment, "--host", host, "--run-dir",
                                    (dir / ("run-" + std::string(host))).string(), "--status-period", "0.2", "--summary-json",
                                    l.summary},
                                   l.log);
    launchers.push_back(l);
  }
  for (const Launcher& l : launchers) ASSERT_GT(l.pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  bool both_up = false;
  while (!both_up && std::chrono::steady_clock::now() < deadline) {
    both_up = true;
    for (const Launcher& l : launchers) both_up = both_up && readFile(l.log).find("| 2/2 up | mocap_a") != std::string::npos;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (const Launcher& l : launchers) {
    EXPECT_TRUE(both_up) << "within 30 s, launcher of host " << l.host << " never showed 2/2 up:\n" << readFile(l.log);
    if (core::signalProcess(l.pid, SIGTERM) == core::SignalResult::kSent) {
      EXPECT_EQ(testutil::waitExit(l.pid, "mannequin-launch --host " + l.host, std::chrono::seconds(20)), 0) << readFile(l.log);
    } else {
      ADD_FAILURE() << "launcher of host " << l.host << " (pid " << l.pid << ") was gone before SIGTERM:\n" << readFile(l.log);
    }
  }
  for (const Launcher& l : launchers) {
    const std::string json = readFile(l.summary);
    const std::string mine = "mocap_" + l.host, other = l.host == "a" ? "mocap_b" : "mocap_a";
    const auto at_mine = json.find("\"name\": \"" + mine + "\"");
    const auto at_other = json.find("\"name\": \"" + other + "\"");
    ASSERT_NE(at_mine, std::string::npos) << json;
    ASSERT_NE(at_other, std::string::npos) << json;
    const std::string entry_mine = json.substr(at_mine, json.find("\"local\"", at_mine) + 16 - at_mine);
    const std::string entry_other = json.substr(at_other, json.find("\"local\"", at_other) + 16 - at_other);
    EXPECT_NE(entry_mine.find("\"state\": \"stopped\", \"starts\": 1"), std::string::npos) << entry_mine;
    EXPECT_NE(entry_mine.find("\"local\": true"), std::string::npos) << entry_mine;
    EXPECT_NE(entry_other.find("\"starts\": 0"), std::string::npos) << entry_other;
    EXPECT_NE(entry_other.find("\"pids\": []"), std::string::npos) << entry_other;
    EXPECT_NE(entry_other.find("\"local\": false"), std::string::npos) << entry_other;
    const auto hb = entry_other.find("\"heartbeats\": ");
    ASSERT_NE(hb, std::string::npos) << entry_other;
    EXPECT_GE(std::stoll(entry_other.substr(hb + 14)), 1) << entry_other;
    EXPECT_NE(entry_other.find("\"state\": \"up\""), std::string::npos) << entry_other;  // from its heartbeats alone
    EXPECT_NE(readFile(l.log).find("on host " + std::string(l.host == "a" ? "b" : "a") + " (not started here)"), std::string::npos)
        << readFile(l.log);
  }
  std::filesystem::remove_all(dir);
}

TEST(EndToEnd, LauncherBvhDrivesTheMannequinAtRateAndStopsCleanly) {
  const auto dir = std::filesystem::temp_directory_path() / ("mq-e2e-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string run = (dir / "run").string();
  const std::string deployment = (dir / "e2e.yaml").string();
  {
    std::ofstream out(deployment);
    out << R"(name: e2e
heartbeat_timeout: 2.0
services:
  - name: mocap
    exec: mannequin-mocap
    args: [--config, configs/sim/mocap_demo.yaml, --heartbeat-period, "0.2"]
    publish: ipc://${RUN_DIR}/mocap
  - name: collision
    exec: mannequin-collision
    args: [--config, configs/sim/collision_demo.yaml, --heartbeat-period, "0.2", --connect, "ipc://${RUN_DIR}/fuzz"]
    publish: ipc://${RUN_DIR}/collision
    connect: [sim]
  - name: sim
    exec: mannequin-sim
    args: [--config, configs/sim/sim_demo.yaml, --heartbeat-period, "0.2", --connect, "ipc://${RUN_DIR}/fuzz"]
    publish: ipc://${RUN_DIR}/sim
    connect: [mocap, collision]
)";
  }
  const std::string summary = (dir / "summary.json").string();
  const std::string log = (dir / "launch.log").string();
  const pid_t launcher = testutil::spawnProcess({std::string(MANNEQUIN_BIN_DIR) + "/mannequin-launch", deployment, "--run-dir", run,
                                                "--status-period", "1", "--summary-json", summary},
                                               log);
  ASSERT_GT(launcher, 0);

  // watch sim.world like a render node would, and play a fuzzer on the topics the services read
  zmq::context_t ctx;
  std::filesystem::create_directories(run);
  transport::Publisher fuzz(ctx, {"fuzzer", {"ipc://" + run + "/fuzz"}});
  transport::Subscriber watch(ctx, {"e2e", {"ipc://" + run + "/sim"}});
  std::vector<v1::WorldState> worlds;
  watch.subscribe(transport::topics::kSimWorld, std::function<void(const v1::WorldState&)>([&](const v1::WorldState& w) {
                    worlds.push_back(w);
                  }));
  std::mt19937 rng(3);
  int garbage = 0;
  // Runs until the launcher has shown every service up, sim.world has flowed for 4 s of simulation time
  // (240 states) and the garbage is sent; the garbage starts once sim.world flows and the three
  // subscriptions to the fuzzer (sim: mocap.frame, collision.contacts; collision: collision.query) have
  // reached it. Then SIGTERM to the launcher.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(40);
  bool all_up = false, launcher_exited = false;
  int status = 0;
  while (!(all_up && worlds.size() >= 240 && garbage >= 300)) {
    if (std::chrono::steady_clock::now() >= deadline) {
      ADD_FAILURE() << "within 40 s: every service up " << all_up << ", " << worlds.size() << " of 240 sim.world, " << garbage
                    << " of 300 garbage messages (fuzzer subscriptions " << fuzz.subscriptions() << " of 3)\n"
                    << readFile(log);
      break;
    }
    if (waitpid(launcher, &status, WNOHANG) == launcher) {
      launcher_exited = true;
      ADD_FAILURE() << "the launcher exited before it was stopped (" << testutil::exitCode(status) << ")\n" << readFile(log);
      break;
    }
    watch.poll(std::chrono::milliseconds(5));
    fuzz.poll();
    if (!all_up) all_up = readFile(log).find("| 3/3 up | mocap") != std::string::npos;
    if (!worlds.empty() && fuzz.subscriptions() >= 3 && garbage < 300) {
      // random bytes, a wrong schema version, NaN poses
      std::string bytes(1 + rng() % 200, '\0');
      for (char& c : bytes) c = static_cast<char>(rng());
      fuzz.publishRaw(garbage % 2 ? "mocap.frame" : "collision.contacts", bytes);
      fuzz.publishRaw("collision.query", bytes);
      v1::MocapFrame f;
      f.mutable_header()->set_schema_version(garbage % 3 == 0 ? 7 : 1);
      f.mutable_header()->set_source("fuzzer");
      f.mutable_header()->set_sequence(garbage + 1);
      auto* b = f.add_bodies();
      b->set_name("hand_l");
      b->set_tracked(true);
      b->mutable_pose()->mutable_position()->set_x(NAN);
      b->mutable_pose()->mutable_orientation()->set_w(1);
      fuzz.publishRaw("mocap.frame", f.SerializeAsString());
      garbage += 1;
    }
  }
  if (!launcher_exited) {
    ASSERT_EQ(core::signalProcess(launcher, SIGTERM), core::SignalResult::kSent);
    EXPECT_EQ(testutil::waitExit(launcher, "mannequin-launch after SIGTERM", std::chrono::seconds(20)), 0) << readFile(log);
  }
  const std::string text = readFile(log);

  // sim.world arrived at ~60 Hz of simulation time, from a calibrated mannequin that moves
  ASSERT_GT(worlds.size(), 100u) << text;
  const auto& first = worlds.front();
  const auto& last = worlds.back();
  const double span = last.sim_time() - first.sim_time();
  const double rate = (worlds.size() - 1) / span;
  EXPECT_NEAR(rate, 60.0, 3.0);
  ASSERT_EQ(last.mannequins_size(), 1);
  EXPECT_TRUE(last.mannequins(0).calibrated());
  EXPECT_EQ(last.mannequins(0).q_size(), 43);
  EXPECT_GT(last.mocap().frame_number(), first.mocap().frame_number() + 100);  // capture time carried end to end
  EXPECT_GT(last.mocap().send_time_ns(), 0);
  double travel = 0, worst_hand = 0, mean_hand = 0;
  for (std::size_t i = 1; i < worlds.size(); ++i) {
    const auto& a = worlds[i - 1].mannequins(0).q();
    const auto& b = worlds[i].mannequins(0).q();
    travel += std::hypot(b[0] - a[0], b[1] - a[1]);
    for (const auto& c : worlds[i].mannequins(0).control_frames())
      if (c.frame() == "hand_l") {
        worst_hand = std::max(worst_hand, c.position_error());
        mean_hand += c.position_error() / static_cast<double>(worlds.size() - 1);
      }
  }
  EXPECT_GT(travel, 0.2) << "the pelvis should follow the capture";
  // the hand follows its body: the controller (configs/control/mocap.yaml), calibrated on the first
  // frame of this capture, keeps a mean error of ~0.012 m (worst ~0.05 m) on the CMU hop; the kinematic
  // tracker gave ~0.1 m (docs/cluster.md). Bound with margin for a loaded machine (live mode).
  EXPECT_LT(mean_hand, 0.05) << "worst " << worst_hand;
  std::printf("hand_l position error over %zu states: mean %.3f m, worst %.3f m\n", worlds.size(), mean_hand, worst_hand);
  // physics on in configs/sim/sim_demo.yaml (sim.world carries the step diagnostics): the physics'
  // floor contacts; the soles never deeper in the floor than the segment margin (0.005 m: the contact
  // rows keep the margin shells from overlapping) and on the floor (≤ 1 cm) in most calibrated worlds
  EXPECT_TRUE(last.has_diagnostics()) << "configs/sim/sim_demo.yaml should run with physics on";
  bool contacts_seen = false;
  std::size_t calibrated = 0, on_floor = 0;
  double lowest = 1e9;
  for (const auto& w : worlds) {
    contacts_seen = contacts_seen || w.mannequins(0).contacts_size() > 0;
    if (!w.mannequins(0).calibrated()) continue;
    ++calibrated;
    const double sole = w.mannequins(0).sole_height();
    EXPECT_GE(sole, -0.005) << "sim.world at step " << w.step() << ": sole below the floor by more than the segment margin";
    lowest = std::min(lowest, sole);
    on_floor += sole <= 0.01;
  }
  EXPECT_TRUE(contacts_seen) << "no sim.world carried floor contacts";
  EXPECT_GT(on_floor, calibrated / 2) << "calibrated worlds with a sole within 1 cm of the floor; lowest sole " << lowest << " m";

  // summary: every service heartbeated, stopped cleanly; garbage counted as malformed
  const std::string json = readFile(summary);
  for (const char* name : {"mocap", "collision", "sim"}) {
    const auto at = json.find(std::string("\"name\": \"") + name + "\"");
    ASSERT_NE(at, std::string::npos) << json;
    const std::string entry = json.substr(at, 200);
    EXPECT_NE(entry.find("\"state\": \"stopped\", \"starts\": 1, \"restarts\": 0, \"last_exit\": \"exit 0\", \"clean_exit\": true"),
              std::string::npos)
        << entry;
  }
  EXPECT_GT(garbage, 100);
  EXPECT_NE(json.find("\"topic\": \"mocap.frame\", \"published\": false"), std::string::npos);
  const auto sub_mocap = json.find("\"topic\": \"mocap.frame\", \"published\": false");
  const auto malformed = json.find("\"malformed\": ", sub_mocap);
  EXPECT_GT(std::stoll(json.substr(malformed + 13)), 100) << json.substr(sub_mocap, 200);
  EXPECT_NE(text.find("| 3/3 up | mocap"), std::string::npos) << text;
  EXPECT_NE(text.find("dropped a malformed message on 'mocap.frame'"), std::string::npos);

  // no process left behind: every pid of the summary is gone
  std::size_t pos = 0;
  int pids = 0;
  while ((pos = json.find("\"pids\": [", pos)) != std::string::npos) {
    pos += 9;
    const pid_t p = static_cast<pid_t>(std::stol(json.substr(pos)));
    EXPECT_GT(p, 0) << json;
    EXPECT_TRUE(core::processGone(p)) << "pid " << p << " still exists";
    ++pids;
  }
  EXPECT_EQ(pids, 3);
  std::filesystem::remove_all(dir);
}

// A demonstration live (docs/demos.md): configs/deployments/demo-ball.yaml as shipped, under mannequin-launch
// for 13 s (the scripted actor lasts 9 s): the sim runs the scenario in its loop on the mocap service's stream
// and goes through its seven states in order, as the offline run does (Demo.Fig49...); the view node, without a
// display, exits 2 and the rest goes on.
TEST(EndToEnd, TheBallDemonstrationDeploymentRunsItsScenarioLive) {
  const auto dir = std::filesystem::temp_directory_path() / ("mq-e2e-demo-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string log = (dir / "launch.log").string();
  const pid_t launcher = testutil::spawnProcess({std::string(MANNEQUIN_BIN_DIR) + "/mannequin-launch", "configs/deployments/demo-ball.yaml",
                                                 "--duration", "13", "--run-dir", (dir / "run").string()},
                                                log);
  ASSERT_GT(launcher, 0);
  const int code = testutil::waitExit(launcher, "mannequin-launch configs/deployments/demo-ball.yaml --duration 13", std::chrono::seconds(60));
  const std::string out = readFile(log);
  // exit 1 only for the view node's failure without a display (exit 2, not restarted); mocap and sim end cleanly
  const bool view_failed = out.find("view failed (exit 2), not restarted") != std::string::npos;
  EXPECT_EQ(code, view_failed ? 1 : 0) << out;
  EXPECT_NE(out.find("sim stopped (exit 0)"), std::string::npos) << out;
  EXPECT_NE(out.find("mocap stopped (exit 0)"), std::string::npos) << out;
  std::size_t at = 0;
  for (const char* state : {"'fall'", "'caught'", "'on_table'", "'off_table'", "'on_floor'", "'kick'", "'rest'"}) {
    const std::size_t next = out.find(std::string("scenario 'ball' at "), at);
    ASSERT_NE(next, std::string::npos) << "no state " << state << " after the previous one:\n" << out;
    const std::size_t line_end = out.find('\n', next);
    EXPECT_NE(out.substr(next, line_end - next).find(std::string("state ") + state), std::string::npos)
        << "expected " << state << " next, got: " << out.substr(next, line_end - next);
    at = line_end;
  }
  std::filesystem::remove_all(dir);
}

// A restarted sim resumes from its checkpoint: mocap (a scripted actor standing 2 m from the origin,
// 1.5 s of capture, then no more frames) and sim under the launcher, the sim with a `checkpoint`. Once
// the capture has ended and the mannequin stands where the actor was, SIGKILL to the sim: the launcher
// restarts it with --resume, and its first sim.world (read like a render node would) has the mannequin
// calibrated where it was, not at the initial pose (standing at the origin, uncalibrated) — nothing else
// could put it there, the mocap is silent. The launcher removes the checkpoint when it stops.
TEST(EndToEnd, ASimKilledWithSigkillResumesWhereItWasFromItsCheckpoint) {
  const auto dir = std::filesystem::temp_directory_path() / ("mq-e2e-resume-" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string run = (dir / "run").string();
  {
    std::ofstream(dir / "mocap.yaml") << "name: mocap\nsource: synthetic\nsynthetic:\n  rate_hz: 120\n  duration: 1.5\n  bodies:\n"
                                         "    - {name: pelvis, center: [2, 1, 0.95]}\n    - {name: head, center: [2, 1, 1.65]}\n"
                                         "    - {name: hand_l, center: [2.3, 1.25, 1.0]}\n    - {name: hand_r, center: [2.3, 0.75, 1.0]}\n"
                                         "    - {name: foot_l, center: [2, 1.1, 0.08]}\n    - {name: foot_r, center: [2, 0.9, 0.08]}\n";
    // the demo's sim config (physics on), without the collision service
    std::ifstream in("configs/sim/sim_demo.yaml");
    std::ofstream out(dir / "sim.yaml");
    for (std::string line; std::getline(in, line);) out << (line.rfind("collision:", 0) == 0 ? "collision: {mode: none}" : line) << "\n";
    std::ofstream(dir / "deploy.yaml") << "name: resume\nheartbeat_timeout: 2.0\nrestart: {policy: on-failure, backoff_initial: 0.2}\n"
                                          "services:\n"
                                          "  - name: mocap\n    exec: mannequin-mocap\n    args: [--config, " << (dir / "mocap.yaml").string()
                                       << ", --heartbeat-period, '0.2']\n    publish: ipc://${RUN_DIR}/mocap\n"
                                          "  - name: sim\n    exec: mannequin-sim\n    args: [--config, " << (dir / "sim.yaml").string()
                                       << ", --heartbeat-period, '0.2']\n    publish: ipc://${RUN_DIR}/sim\n    connect: [mocap]\n"
                                          "    checkpoint: ${RUN_DIR}/sim.checkpoint\n";
  }
  const std::string checkpoint = run + "/sim.checkpoint";
  const std::string log = (dir / "launch.log").string();
  const pid_t launcher = testutil::spawnProcess({std::string(MANNEQUIN_BIN_DIR) + "/mannequin-launch", (dir / "deploy.yaml").string(),
                                                "--run-dir", run, "--status-period", "0.2", "--status-json",
                                                (dir / "status.json").string()},
                                               log);
  ASSERT_GT(launcher, 0);
  zmq::context_t ctx;
  transport::Subscriber watch(ctx, {"e2e", {"ipc://" + run + "/sim"}});
  std::vector<v1::WorldState> worlds;
  watch.subscribe(transport::topics::kSimWorld,
                  std::function<void(const v1::WorldState&)>([&](const v1::WorldState& w) { worlds.push_back(w); }));
  const auto stopLauncher = [&] {
    if (core::signalProcess(launcher, SIGTERM) == core::SignalResult::kSent)
      testutil::waitExit(launcher, "mannequin-launch after SIGTERM", std::chrono::seconds(20));
  };
  // phase 1: calibrated, the capture over (its last frame number unchanged for 0.5 s), a checkpoint written
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(40);
  std::uint64_t last_frame = 0;
  auto frame_since = std::chrono::steady_clock::now();
  bool settled = false;
  while (!settled) {
    if (std::chrono::steady_clock::now() >= deadline) {
      stopLauncher();
      FAIL() << "within 40 s, no calibrated sim.world after the capture's end with a checkpoint (" << worlds.size()
             << " sim.world)\n" << readFile(log);
    }
    watch.poll(std::chrono::milliseconds(10));
    if (worlds.empty() || !worlds.back().mannequins(0).calibrated()) continue;
    if (worlds.back().mocap().frame_number() != last_frame) {
      last_frame = worlds.back().mocap().frame_number();
      frame_since = std::chrono::steady_clock::now();
    }
    settled = std::chrono::steady_clock::now() - frame_since > std::chrono::milliseconds(500) && std::filesystem::exists(checkpoint);
  }
  // the live status file (--status-json) names the sim, up, with its heartbeat statistics
  const std::string status = readFile((dir / "status.json").string());
  EXPECT_NE(status.find("{\"name\": \"sim\", \"state\": \"up\""), std::string::npos) << status;
  EXPECT_NE(status.find("\"dropped_steps\": "), std::string::npos) << status;
  const v1::WorldState before = worlds.back();
  const double x = before.mannequins(0).q(0), y = before.mannequins(0).q(1), z = before.mannequins(0).q(2);
  ASSERT_GT(std::hypot(x, y), 1.5) << "the mannequin should stand under the actor, 2.2 m from the origin";

  // phase 2: SIGKILL to the sim (its pid from the launcher's "started sim (pid N)")
  const std::string text = readFile(log);
  const auto at = text.find("started sim (pid ");
  ASSERT_NE(at, std::string::npos) << text;
  const pid_t sim = static_cast<pid_t>(std::stol(text.substr(at + 17)));
  ASSERT_GT(sim, 0);
  ASSERT_EQ(core::signalProcess(sim, SIGKILL), core::SignalResult::kSent);
  // phase 3: the restarted sim's first sim.world (sequence starts again at 1 in a new process)
  const std::size_t seen = worlds.size();
  deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  const v1::WorldState* resumed = nullptr;
  while (resumed == nullptr) {
    if (std::chrono::steady_clock::now() >= deadline) {
      stopLauncher();
      FAIL() << "within 30 s of the SIGKILL, no sim.world from a restarted sim\n" << readFile(log);
    }
    watch.poll(std::chrono::milliseconds(10));
    for (std::size_t i = seen; i < worlds.size() && resumed == nullptr; ++i)
      if (worlds[i].header().sequence() < before.header().sequence()) resumed = &worlds[i];
  }
  const v1::MannequinState& m = resumed->mannequins(0);
  EXPECT_TRUE(m.calibrated()) << "the restarted sim should have the calibration back";
  EXPECT_LT(std::hypot(m.q(0) - x, m.q(1) - y), 0.02) << "resumed at (" << m.q(0) << ", " << m.q(1) << "), was at (" << x << ", " << y << ")";
  EXPECT_NEAR(m.q(2), z, 0.02);
  // the step count continues from the checkpoint, written at most every 0.1 s (100 steps) at a sim.world
  // (every 17 steps): at most ~120 steps before the last state seen (a fresh sim starts at 0)
  EXPECT_GT(resumed->step() + 200, before.step()) << "the step count continues from the checkpoint";
  const std::string after = readFile(log);
  EXPECT_NE(after.find("--resume " + checkpoint), std::string::npos) << after;
  EXPECT_NE(after.find("resumed from " + checkpoint), std::string::npos) << after;
  ASSERT_EQ(core::signalProcess(launcher, SIGTERM), core::SignalResult::kSent);
  // exit 1: a service of the run exited otherwise than 0 (the SIGKILL), by the launcher's design
  EXPECT_EQ(testutil::waitExit(launcher, "mannequin-launch after SIGTERM", std::chrono::seconds(20)), 1) << readFile(log);
  EXPECT_FALSE(std::filesystem::exists(checkpoint)) << "the launcher removes the checkpoint when it stops";
  std::filesystem::remove_all(dir);
}
