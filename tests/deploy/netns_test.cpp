// The VR room for real on one machine: three network namespaces joined by veth pairs (a bridge in the sim's
// namespace), one "host" each, the same multi-host deployment with CURVE, `mannequin-launch D.yaml --host X`
// started in each namespace with `ip netns exec`: mocap on host mocap (10.77.0.1), sim + collision on host
// sim (10.77.0.2), and on host station (10.77.0.3) a launcher with no service (it monitors the room) and
// the consumer, mannequin-record with a listed client key. Asserted: every launcher shows the whole room
// up (3/3, from heartbeats over tcp+CURVE across namespaces); the recorder gets sim.world with increasing
// sequence numbers, computed from mocap frames that crossed from the mocap namespace (the frame number of
// the mocap reference advances); a recorder with an unlisted key gets nothing and the sim logs the refusal.
// Needs root (CAP_NET_ADMIN, `ip netns`): skipped with a message otherwise. The namespaces (and every process
// in them) are removed in all paths by the Room guard, also after a failed assertion.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "../common/child_process.hpp"
#include "../common/netns_room.hpp"
#include "mannequin/core/process.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/transport/security.hpp"
#include "mannequin/v1/world.pb.h"

using namespace mannequin;
namespace fs = std::filesystem;

using namespace mannequin::testutil::netns;

TEST(NetnsRoom, WorldStatesFlowAcrossThreeHostsOverTcpWithCurveAndAnUnlistedKeyGetsNothing) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root (CAP_NET_ADMIN) to create network namespaces and veth pairs";
  if (ipTool().empty()) GTEST_SKIP() << "no 'ip' tool (iproute2) found";
  if (!transport::hasCurve()) GTEST_SKIP() << "libzmq without CURVE";
  const fs::path dir = fs::temp_directory_path() / ("mq-netns-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "keys");
  Room room(dir);
  if (const std::string e = room.build(); !e.empty()) {
    if (e.find("Operation not permitted") != std::string::npos || e.find("Permission denied") != std::string::npos)
      GTEST_SKIP() << "no privilege to create network namespaces here: " << e;
    FAIL() << e;
  }

  writeKeyPairs(dir / "keys", {"mocap", "collision", "sim", "launch.mocap", "launch.sim", "launch.station", "operator", "stranger"});
  const std::string stranger = transport::readKeyFile((dir / "keys" / "stranger.key").string(), false);
  const fs::path deployment = dir / "room.yaml";
  std::ofstream(deployment) << R"(name: netns-room
heartbeat_timeout: 3.0
hosts:
  - {name: mocap, address: 10.77.0.1}
  - {name: sim, address: 10.77.0.2}
  - {name: station, address: 10.77.0.3}
security: {key_dir: keys, clients: [operator]}
services:
  - name: mocap
    host: mocap
    exec: mannequin-mocap
    args: [--config, configs/sim/mocap_demo.yaml, --heartbeat-period, "0.2"]
    publish: tcp://*:5601
  - name: collision
    host: sim
    exec: mannequin-collision
    args: [--config, configs/sim/collision_demo.yaml, --heartbeat-period, "0.2"]
    publish: tcp://*:5602
    connect: [sim]
  - name: sim
    host: sim
    exec: mannequin-sim
    args: [--config, configs/sim/sim_demo.yaml, --heartbeat-period, "0.2"]
    publish: tcp://*:5603
    connect: [mocap, collision]
)";

  const std::string bin = MANNEQUIN_BIN_DIR;
  std::vector<fs::path> logs;
  std::vector<pid_t> launchers;
  for (const char* host : {"mocap", "sim", "station"}) {
    logs.push_back(dir / (std::string(host) + ".log"));
    launchers.push_back(room.start(host,
                                   {bin + "/mannequin-launch", deployment.string(), "--host", host, "--run-dir",
                                    (dir / ("run-" + std::string(host))).string(), "--status-period", "0.5", "--no-tty"},
                                   logs.back()));
    ASSERT_GT(launchers.back(), 0);
  }
  auto allLogs = [&] {
    std::string s;
    for (const auto& l : logs) s += "---- " + l.filename().string() + "\n" + readFile(l);
    return s;
  };
  // every launcher, the station's too (it starts nothing), sees the whole room up from the heartbeats
  ASSERT_TRUE(waitForText(logs, "| 3/3 up | mocap", std::chrono::seconds(60))) << "the room was not up everywhere within 60 s\n"
                                                                                << allLogs();
  // the consumer on the station: sim.world over tcp+CURVE from the sim's namespace
  const fs::path good = dir / "good.mcap", bad = dir / "bad.mcap";
  const pid_t recorder = room.start("station",
                                    {bin + "/mannequin-record", deployment.string(), "--client-key",
                                     (dir / "keys" / "operator.key_secret").string(), "--topics", "sim.world", "--duration", "4",
                                     "--progress", "0", "--out", good.string()},
                                    dir / "record-good.log");
  const pid_t intruder = room.start("station",
                                    {bin + "/mannequin-record", deployment.string(), "--client-key",
                                     (dir / "keys" / "stranger.key_secret").string(), "--topics", "sim.world", "--duration", "4",
                                     "--progress", "0", "--out", bad.string()},
                                    dir / "record-bad.log");
  ASSERT_GT(recorder, 0);
  ASSERT_GT(intruder, 0);
  EXPECT_EQ(room.wait(recorder, "mannequin-record (listed key)", std::chrono::seconds(30)), 0) << readFile(dir / "record-good.log");
  EXPECT_EQ(room.wait(intruder, "mannequin-record (unlisted key)", std::chrono::seconds(30)), 0) << readFile(dir / "record-bad.log");

  const std::vector<v1::WorldState> worlds = worldsIn(good);
  ASSERT_GE(worlds.size(), 30u) << "sim.world received by the listed recorder in 4 s\n" << readFile(dir / "record-good.log");
  for (std::size_t i = 1; i < worlds.size(); ++i)
    ASSERT_GT(worlds[i].header().sequence(), worlds[i - 1].header().sequence()) << "sim.world " << i;
  EXPECT_EQ(worlds.front().header().source(), "sim");
  EXPECT_GT(worlds.back().mocap().frame_number(), worlds.front().mocap().frame_number())
      << "the sim's mocap frames (from the mocap namespace) did not advance";
  EXPECT_EQ(messagesIn(bad), 0u) << "a recorder with an unlisted key received messages";
  EXPECT_TRUE(waitForText({logs[1]}, "refused CURVE client key " + stranger, std::chrono::seconds(10)))
      << "the sim host did not log the refused key\n" << readFile(logs[1]);

  for (std::size_t i = 0; i < launchers.size(); ++i)
    EXPECT_EQ(room.stop(launchers[i], "mannequin-launch in " + logs[i].filename().string()), 0) << allLogs();
  std::printf("netns room: %zu sim.world states recorded on the station, sequence %llu..%llu, mocap frame %u..%u\n", worlds.size(),
              static_cast<unsigned long long>(worlds.front().header().sequence()),
              static_cast<unsigned long long>(worlds.back().header().sequence()), static_cast<unsigned>(worlds.front().mocap().frame_number()),
              static_cast<unsigned>(worlds.back().mocap().frame_number()));
}
