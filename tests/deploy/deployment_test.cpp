// Deployment files: command lines, ${RUN_DIR}, restart options, errors with FILE:LINE.
#include <gtest/gtest.h>

#include "mannequin/deploy/deployment.hpp"
#include "mannequin/core/config.hpp"

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
  for (const char* f : {"configs/deployments/single-host.yaml", "configs/deployments/single-host-view.yaml"}) {
    const Deployment d = loadDeployment(f);
    EXPECT_GE(d.services.size(), 1u) << f;
  }
}
