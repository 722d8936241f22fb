// The one service loop: RUNNING while it runs, STOPPING after; it ends on the stop flag, on --duration
// and when the iteration says so; heartbeats are published on their period; the final hook runs once.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>

#include "mannequin/core/clock.hpp"
#include "mannequin/service/runtime.hpp"

using namespace mannequin;

namespace {

struct Rig {
  zmq::context_t context;
  transport::Publisher pub{context, {"looptest", {"ipc:///tmp/mannequin-loop-test-" + std::to_string(getpid())}}};
  transport::HealthReporter health{pub, "looptest", nullptr, 0.02};
  std::atomic<bool> stop{false};
};

TEST(ServiceLoop, RunningWhileItRunsStoppingAfterAndTheStopFlagEndsIt) {
  Rig r;
  EXPECT_EQ(r.health.state(), v1::SERVICE_STATE_STARTING);
  int iterations = 0, stops = 0;
  bool running_inside = true;
  service::ServiceLoop loop(r.health, r.stop, 0.0);
  const int rc = loop.run(
      [&] {
        running_inside = running_inside && r.health.state() == v1::SERVICE_STATE_RUNNING;
        if (++iterations == 5) r.stop.store(true);
        return true;
      },
      {}, [&] { ++stops; });
  EXPECT_EQ(rc, 0);
  EXPECT_EQ(iterations, 5);
  EXPECT_TRUE(running_inside);
  EXPECT_EQ(stops, 1);
  EXPECT_EQ(r.health.state(), v1::SERVICE_STATE_STOPPING);
}

TEST(ServiceLoop, TheIterationCanEndIt) {
  Rig r;
  int iterations = 0;
  service::ServiceLoop(r.health, r.stop).run([&] { return ++iterations < 3; });
  EXPECT_EQ(iterations, 3);
  EXPECT_EQ(r.health.state(), v1::SERVICE_STATE_STOPPING);
}

TEST(ServiceLoop, DurationEndsItAndHeartbeatsComeOnTheirPeriod) {
  Rig r;
  int heartbeats = 0;
  const std::int64_t t0 = core::steadyNs();
  service::ServiceLoop loop(r.health, r.stop, 0.2);
  loop.run(
      [&] {
        usleep(1000);
        return true;
      },
      [&] { ++heartbeats; });
  const double took = static_cast<double>(core::steadyNs() - t0) * 1e-9;
  EXPECT_GE(took, 0.2);
  EXPECT_LT(took, 2.0) << "the loop did not stop at its duration";
  EXPECT_TRUE(loop.stopping());
  // 0.2 s at a 0.02 s period: heartbeats were published along the way, not only at start and end
  EXPECT_GE(heartbeats, 3);
}

TEST(ServiceKit, EndpointsFromTheCommandLineWinOverTheConfig) {
  const core::ConfigNode config =
      core::ConfigNode::parse("name: fromfile\npublish: ipc:///tmp/a\nconnect: [ipc:///tmp/b]\n", "svc.yaml");
  service::CommonOptions o;
  service::Endpoints e = service::resolveEndpoints(o, config, "svc");
  EXPECT_EQ(e.name, "fromfile");
  EXPECT_EQ(e.publish, std::vector<std::string>{"ipc:///tmp/a"});
  EXPECT_EQ(e.connect, std::vector<std::string>{"ipc:///tmp/b"});
  o.name = "cli";
  o.publish = {"tcp://127.0.0.1:1"};
  e = service::resolveEndpoints(o, config, "svc");
  EXPECT_EQ(e.name, "cli");
  EXPECT_EQ(e.publish, std::vector<std::string>{"tcp://127.0.0.1:1"});
  o = {};
  o.config = "svc.yaml";
  EXPECT_THROW(service::resolveEndpoints(o, core::ConfigNode::parse("name: x\n", "svc.yaml"), "svc"), core::ConfigError);
}

}  // namespace
