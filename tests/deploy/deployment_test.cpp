// Deployment files: command lines, ${RUN_DIR}, restart options, errors with FILE:LINE.
#include <gtest/gtest.h>

#include "mannequin/deploy/deployment.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/service/runtime.hpp"
#include "mannequin/transport/security.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

using namespace mannequin::deploy;

TEST(Deployment, CommandLinesConnectByServiceName) {
  const Deployment d = parseDeployment(R"(name: demo
run_dir: /tmp/run
restart: {policy: always, max_restarts: 2}
services:
  - name: mocap
    exec: mannequin-mocap
    args: [--config, a.yaml, --out, "${RUN_DIR}/x"]
    publish: ipc://${RUN_DIR}/mocap
  - name: sim
    exec: ./bin/mannequin-sim
    publish: tcp://127.0.0.1:7001
    connect: [mocap]
    restart: {policy: never}
)",
                                       "demo.yaml");
  EXPECT_EQ(d.run_dir, "/tmp/run");
  ASSERT_EQ(d.services.size(), 2u);
  EXPECT_EQ(d.commandLine(0), (std::vector<std::string>{"mannequin-mocap", "--name", "mocap", "--publish", "ipc:///tmp/run/mocap",
                                                        "--config", "a.yaml", "--out", "/tmp/run/x"}));
  EXPECT_EQ(d.commandLine(1), (std::vector<std::string>{"./bin/mannequin-sim", "--name", "sim", "--publish",
                                                        "tcp://127.0.0.1:7001", "--connect", "ipc:///tmp/run/mocap"}));
  EXPECT_EQ(d.services[0].restart.policy, RestartPolicy::kAlways);
  EXPECT_EQ(d.services[0].restart.max_restarts, 2);
  EXPECT_EQ(d.services[1].restart.policy, RestartPolicy::kNever);
  EXPECT_EQ(d.services[1].restart.max_restarts, 2);  // inherited
  // a checkpoint: --checkpoint FILE always, --resume FILE when asked (a restart); an empty one refused
  const Deployment c = parseDeployment(
      "name: x\nservices:\n  - {name: sim, exec: s, publish: 'ipc://${RUN_DIR}/s', checkpoint: '${RUN_DIR}/sim.checkpoint'}\n",
      "x.yaml", "/r");
  EXPECT_EQ(c.services[0].checkpoint, "/r/sim.checkpoint");
  EXPECT_EQ(c.commandLine(0), (std::vector<std::string>{"s", "--name", "sim", "--publish", "ipc:///r/s", "--checkpoint", "/r/sim.checkpoint"}));
  EXPECT_EQ(c.commandLine(0, true), (std::vector<std::string>{"s", "--name", "sim", "--publish", "ipc:///r/s", "--checkpoint",
                                                              "/r/sim.checkpoint", "--resume", "/r/sim.checkpoint"}));
  EXPECT_THROW(parseDeployment("name: x\nservices:\n  - {name: sim, exec: s, publish: 'ipc:///r/s', checkpoint: ''}\n", "x.yaml"),
               mannequin::core::ConfigError);
  // the run dir can be given from outside
  EXPECT_EQ(parseDeployment("name: x\nservices:\n  - {name: a, exec: b, publish: 'ipc://${RUN_DIR}/a'}\n", "x.yaml", "/r")
                .services[0].publish,
            "ipc:///r/a");
}

TEST(Deployment, ErrorsNameFileLineAndField) {
  auto expectError = [](const std::string& yaml, const std::string& what) {
    try {
      parseDeployment(yaml, "d.yaml");
      ADD_FAILURE() << "no error for\n" << yaml;
    } catch (const mannequin::core::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expectError("name: x\nservices: []\n", "d.yaml:2: field 'services': no services");
  expectError("name: x\nservices:\n  - {name: a, exec: b, publish: 'ipc:///a'}\n  - {name: a, exec: b, publish: 'ipc:///b'}\n",
              "d.yaml:4: field 'services[1].name': duplicate service name 'a'");
  expectError("name: x\nservices:\n  - {name: a, exec: b, publish: 'ipc:///a', connect: [z]}\n",
              "field 'services[0].connect': no service named 'z'");
  expectError("name: x\nservices:\n  - {name: a, exec: b, publish: 'udp://x:1'}\n", "field 'services[0].publish'");
  expectError("name: x\nservices:\n  - {name: a, exec: b, publish: 'tcp://127.0.0.1:0'}\n", "ephemeral port");
  expectError("name: x\nservices:\n  - {name: a, exec: b}\n", "missing required key 'publish'");
  expectError("name: x\nservices:\n  - {name: a, exec: b, publish: 'ipc:///a', restart: {policy: sometimes}}\n",
              "d.yaml:3: field 'services[0].restart.policy': expected never, on-failure or always, got 'sometimes'");
  expectError("name: x\nrestart: {max_restarts: -1}\nservices:\n  - {name: a, exec: b, publish: 'ipc:///a'}\n",
              "d.yaml:2: field 'restart.max_restarts': -1 is outside [0, ");
  expectError("name: x\nheartbeat_timout: 3\nservices: []\n", "d.yaml:2: field 'heartbeat_timout': unknown key");
  expectError("name: x\nservices:\n  - {name: a, exec: b, publish: 'ipc:///a', restart: {backoff_initial: -1}}\n",
              "backoff_initial");
  try {
    loadDeployment("/nonexistent/deployment.yaml");
    ADD_FAILURE() << "no error for a missing deployment file";
  } catch (const mannequin::core::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/deployment.yaml:0: cannot read the file", 0), 0u) << e.what();
  }
}

TEST(Deployment, ShippedDeploymentsParse) {
  for (const char* f : {"configs/deployments/single-host.yaml", "configs/deployments/single-host-view.yaml",
                        "configs/deployments/cave.yaml"}) {
    const Deployment d = loadDeployment(f);
    EXPECT_GE(d.services.size(), 1u) << f;
    EXPECT_FALSE(d.multiHost()) << f;
  }
  // the demonstrations live (docs/demos.md): mocap and sim (the jump with collision), a view
  for (const char* demo : {"jump", "ball", "piano", "drill", "waiter", "pilot", "rotor"}) {
    const std::string f = std::string("configs/deployments/demo-") + demo + ".yaml";
    const Deployment d = loadDeployment(f);
    EXPECT_FALSE(d.multiHost()) << f;
    bool has_sim = false;
    for (const ServiceSpec& s : d.services) {
      has_sim = has_sim || s.exec == "mannequin-sim";
      for (const std::string& a : s.args) {  // every file an argument names is shipped
        if (a.rfind("configs/", 0) == 0) {
          EXPECT_TRUE(std::filesystem::exists(a)) << f << ": " << s.name << ": " << a;
        }
      }
    }
    EXPECT_TRUE(has_sim) << f;
  }
  // the VR room: one mocap host, one sim host (sim + collision), four render hosts (a wall each)
  const Deployment room = loadDeployment("configs/deployments/vr-room.yaml");
  ASSERT_TRUE(room.multiHost());
  EXPECT_EQ(room.hostNames(), "mocap-pc, sim-pc, render-front, render-left, render-right, render-floor");
  std::map<std::string, std::vector<std::string>> on;
  for (const ServiceSpec& s : room.services) on[s.host].push_back(s.name);
  EXPECT_EQ(on["mocap-pc"], (std::vector<std::string>{"mocap"}));
  EXPECT_EQ(on["sim-pc"], (std::vector<std::string>{"collision", "sim"}));
  for (const char* wall : {"front", "left", "right", "floor"})
    EXPECT_EQ(on[std::string("render-") + wall], (std::vector<std::string>{std::string("wall_") + wall}));
  EXPECT_EQ(room.addressOf("sim"), "tcp://10.0.0.11:5603");
}

namespace {
const char* kTwoHosts = R"(name: room
hosts:
  - {name: a, address: 10.1.0.1}
  - {name: b, address: fe80::2}
services:
  - name: mocap
    host: a
    exec: mannequin-mocap
    publish: tcp://*:5601
  - name: sim
    host: b
    exec: mannequin-sim
    publish: tcp://0.0.0.0:5601
    connect: [mocap, render]
  - name: render
    host: a
    exec: mannequin-render
    publish: tcp://10.1.0.1:5602
    connect: [sim]
security: {key_dir: /nonexistent/keys, clients: [operator]}
)";

// kTwoHosts with its keys in a temporary directory: every service's, both launchers', the client's
class DeploymentKeys : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!mannequin::transport::hasCurve()) GTEST_SKIP() << "libzmq without CURVE";
    dir = std::filesystem::temp_directory_path() /
          ("mq-keys-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "-" + std::to_string(getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    for (const char* n : {"mocap", "sim", "render", "launch.a", "launch.b", "operator", "stranger"}) {
      const auto k = mannequin::transport::generateCurveKeyPair();
      mannequin::transport::writeKeyFile((dir / (std::string(n) + ".key_secret")).string(), k.secret_key, "secret", 0600);
      mannequin::transport::writeKeyFile((dir / (std::string(n) + ".key")).string(), k.public_key, "public", 0644);
      pub[n] = k.public_key;
    }
    std::string yaml = kTwoHosts;
    yaml.replace(yaml.find("/nonexistent/keys"), 17, dir.string());
    d = parseDeployment(yaml, "room.yaml", (dir / "run").string());
  }
  void TearDown() override { std::filesystem::remove_all(dir); }
  std::string checkError(const std::string& host) {
    try {
      checkKeys(d, host);
    } catch (const mannequin::core::ConfigError& e) {
      return e.what();
    }
    return "no error";
  }
  std::filesystem::path dir;
  std::map<std::string, std::string> pub;
  Deployment d;
};
}  // namespace

TEST(Deployment, MultiHostServicesBindOnTheirHostAndTheOthersConnectToItsAddress) {
  const Deployment d = parseDeployment(kTwoHosts, "room.yaml", "/r");
  ASSERT_EQ(d.hosts.size(), 2u);
  EXPECT_EQ(d.services[0].publish, "tcp://*:5601");
  EXPECT_EQ(d.services[0].address, "tcp://10.1.0.1:5601");
  EXPECT_EQ(d.services[1].address, "tcp://[fe80::2]:5601");  // an IPv6 host address in brackets
  EXPECT_EQ(d.services[2].address, "tcp://10.1.0.1:5602");   // bound on one interface: as written
  // binds its own endpoint, connects to the others' addresses
  EXPECT_EQ(d.commandLine(1), (std::vector<std::string>{"mannequin-sim", "--name", "sim", "--publish", "tcp://0.0.0.0:5601",
                                                        "--connect", "tcp://10.1.0.1:5601", "--connect", "tcp://10.1.0.1:5602",
                                                        "--security", "/r/security/sim.yaml"}));
  EXPECT_TRUE(d.runsOn(0, "a"));
  EXPECT_FALSE(d.runsOn(1, "a"));
  EXPECT_TRUE(d.runsOn(1, "b"));
  // a single-host deployment runs everything here, connecting where it binds
  const Deployment single = parseDeployment("name: x\nservices:\n  - {name: a, exec: b, publish: 'tcp://127.0.0.1:7001'}\n", "x.yaml");
  EXPECT_TRUE(single.runsOn(0, ""));
  EXPECT_EQ(single.services[0].address, "tcp://127.0.0.1:7001");
}

TEST(Deployment, SingleHostBindsIpcOrLoopbackOnly) {
  for (const char* ok : {"ipc:///tmp/a", "tcp://127.0.0.1:7001", "tcp://localhost:7001", "tcp://[::1]:7001", "tcp://lo:7001"})
    EXPECT_NO_THROW(parseDeployment(std::string("name: x\nservices:\n  - {name: a, exec: b, publish: '") + ok + "'}\n", "x.yaml"))
        << ok;
  for (const char* open : {"tcp://*:7001", "tcp://0.0.0.0:7001", "tcp://10.0.0.1:7001", "tcp://eth0:7001", "tcp://[::]:7001"}) {
    try {
      parseDeployment(std::string("name: x\nservices:\n  - {name: a, exec: b, publish: '") + open + "'}\n", "x.yaml");
      ADD_FAILURE() << open << " accepted in a single-host deployment";
    } catch (const mannequin::core::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("x.yaml:3: field 'services[0].publish': '" + std::string(open) +
                                           "' is reachable from other machines"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(Deployment, MultiHostErrorsNameFileLineAndField) {
  auto expectError = [](std::string yaml, const std::string& from, const std::string& to, const std::string& what) {
    const auto at = yaml.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    yaml.replace(at, from.size(), to);
    try {
      parseDeployment(yaml, "room.yaml");
      ADD_FAILURE() << "no error for\n" << yaml;
    } catch (const mannequin::core::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expectError(kTwoHosts, "    host: b\n", "    host: c\n", "room.yaml:11: field 'services[1].host': unknown host 'c' (hosts: a, b)");
  expectError(kTwoHosts, "    host: b\n", "", "room.yaml:10: field 'services[1]': service 'sim' is on no host");
  expectError(kTwoHosts, "{name: b, address", "{name: a, address", "room.yaml:4: field 'hosts[1].name': duplicate host name 'a'");
  expectError(kTwoHosts, "address: 10.1.0.1}", "address: 'tcp://10.1.0.1'}", "field 'hosts[0].address': expected an IP address");
  expectError(kTwoHosts, "name: sim\n", "name: mocap\n", "room.yaml:10: field 'services[1].name': duplicate service name 'mocap'");
  expectError(kTwoHosts, "tcp://*:5601", "ipc:///tmp/mocap", "field 'services[0].publish': a service of a multi-host deployment publishes on tcp");
  expectError(kTwoHosts, "tcp://*:5601", "tcp://127.0.0.1:5601", "'tcp://127.0.0.1:5601' is loopback only");
  expectError(kTwoHosts, "tcp://10.1.0.1:5602", "tcp://10.1.0.1:5601",
              "room.yaml:18: field 'services[2].publish': 'tcp://10.1.0.1:5601' is already bound by service 'mocap' on host 'a'");
  expectError(kTwoHosts, "hosts:\n  - {name: a, address: 10.1.0.1}\n  - {name: b, address: fe80::2}\n", "hosts: []\n",
              "room.yaml:2: field 'hosts': no hosts");
  expectError(kTwoHosts, "security: {key_dir: /nonexistent/keys, clients: [operator]}\n", "",
              "room.yaml:3: field 'hosts': a multi-host deployment needs 'security'");
  expectError(kTwoHosts, "clients: [operator]", "clients: [operator], keydir: x", "room.yaml:20: field 'security.keydir': unknown key");
  expectError("name: x\nservices:\n  - {name: a, host: h, exec: b, publish: 'ipc:///a'}\n", "name: x", "name: x",
              "room.yaml:3: field 'services[0].host': this deployment has no 'hosts'");
}

TEST_F(DeploymentKeys, EveryKeyIsCheckedBeforeAnythingStartsNamingWhoseItIs) {
  EXPECT_EQ(checkError("a"), "no error");
  EXPECT_EQ(checkError(""), "no error");  // every host's secrets (the machine the keys were made on)
  const std::string at = "room.yaml:20: field 'security.key_dir': ";
  // another host's secret is not needed on host a
  std::filesystem::remove(dir / "sim.key_secret");
  EXPECT_EQ(checkError("a"), "no error");
  std::string e = checkError("b");
  EXPECT_NE(e.find(at + (dir / "sim.key_secret").string() + ": cannot read key file"), std::string::npos) << e;
  EXPECT_NE(e.find("the secret key of service 'sim' on host b"), std::string::npos) << e;
  EXPECT_NE(e.find("mannequin-keys generate sim --dir " + dir.string()), std::string::npos) << e;
  EXPECT_NE(checkError("").find("sim.key_secret"), std::string::npos);
  // every public key is needed on every host (a publisher admits them all)
  std::filesystem::remove(dir / "operator.key");
  e = checkError("a");
  EXPECT_NE(e.find(at + (dir / "operator.key").string()), std::string::npos) << e;
  EXPECT_NE(e.find("the public key of client 'operator'"), std::string::npos) << e;
  std::filesystem::copy_file(dir / "stranger.key", dir / "operator.key");
  // a world-readable secret
  std::filesystem::permissions(dir / "mocap.key_secret", std::filesystem::perms::others_read, std::filesystem::perm_options::add);
  e = checkError("a");
  EXPECT_NE(e.find(at + (dir / "mocap.key_secret").string() + ": secret key file is readable by others"), std::string::npos) << e;
  std::filesystem::permissions(dir / "mocap.key_secret", std::filesystem::perms::others_read, std::filesystem::perm_options::remove);
  // a secret that is not the pair of the public key
  std::filesystem::remove(dir / "launch.a.key_secret");
  std::filesystem::copy_file(dir / "stranger.key_secret", dir / "launch.a.key_secret");
  e = checkError("a");
  EXPECT_NE(e.find(at + (dir / "launch.a.key_secret").string() + ": not the secret key of " + (dir / "launch.a.key").string()),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("the key of the launcher of host a"), std::string::npos) << e;
}

TEST_F(DeploymentKeys, EachServiceIsGivenItsKeysTheKeysOfItsPublishersAndTheAdmittedKeys) {
  // sim (host b) connects to mocap and render (host a) by their addresses
  const auto argv = d.commandLine(1);
  ASSERT_GE(argv.size(), 2u);
  EXPECT_EQ(argv[argv.size() - 2], "--security");
  EXPECT_EQ(argv.back(), (dir / "run" / "security" / "sim.yaml").string());
  std::filesystem::create_directories(dir / "run");
  const std::string file = (dir / "run" / "sim.yaml").string();
  std::ofstream(file) << d.securityFileText(1);
  const mannequin::service::Security s = mannequin::service::readSecurityFile(file, true);
  ASSERT_TRUE(s.server && s.client);
  EXPECT_EQ(s.client->public_key, pub["sim"]);
  EXPECT_EQ(s.client->server_keys, (std::map<std::string, std::string>{{"tcp://10.1.0.1:5601", pub["mocap"]},
                                                                      {"tcp://10.1.0.1:5602", pub["render"]}}));
  // every publisher admits the services, both launchers and the client; nobody else
  EXPECT_EQ(s.server->authorized_keys, (std::vector<std::string>{pub["mocap"], pub["sim"], pub["render"], pub["launch.a"],
                                                                  pub["launch.b"], pub["operator"]}));
  // mocap connects to nobody: no servers, still a server of its own
  std::ofstream(file) << d.securityFileText(0);
  const mannequin::service::Security m = mannequin::service::readSecurityFile(file, false);
  EXPECT_TRUE(m.server.has_value());
  EXPECT_FALSE(m.client.has_value());
  // a monitor's (or recorder's) keys: each service's public key by its address
  const auto c = d.clientKeys((dir / "operator.key_secret").string());
  EXPECT_EQ(c.public_key, pub["operator"]);
  EXPECT_EQ(c.server_keys.size(), 3u);
  EXPECT_EQ(c.server_keys.at("tcp://[fe80::2]:5601"), pub["sim"]);
}
