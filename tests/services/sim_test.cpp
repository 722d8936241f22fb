// the sim service: its config, replay mode (deterministic bytes), live mode over ipc, offline runs
// (libs/sim itself: tests/sim/world_test.cpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "mannequin/math/so3.hpp"
#include "mannequin/mocap/source.hpp"
#include "mannequin/proto/schema.hpp"
#include "mannequin/recording/mcap_writer.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/simservice/messages.hpp"
#include "mannequin/simservice/offline.hpp"
#include "mannequin/simservice/sim_service.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/subscriber.hpp"
#include "mannequin/transport/topics.hpp"
#include "../common/child_process.hpp"
#include "../common/pose.hpp"
#include "../common/tool_run.hpp"

using namespace mannequin;
using namespace mannequin::sim;

namespace {
using mannequin::testing::pose;

}  // namespace

TEST(SimConfig, ErrorsNameFileLineAndField) {
  auto expectError = [](const std::string& yaml, const std::string& what) {
    try {
      simservice::parseSimConfig(core::ConfigNode::parse(yaml, "sim.yaml"));
      ADD_FAILURE() << "no error for\n" << yaml;
    } catch (const core::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << "got: " << e.what();
    }
  };
  const std::string m = "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, control_frames: {hand_l: hand_l}}\n";
  expectError("mode: fast\n" + m, "sim.yaml:1: field 'mode': expected live or replay");
  expectError("step: 0\n" + m, "field 'step'");
  expectError("step: 0.001\nworld_rate: 5000\n" + m, "field 'world_rate'");
  expectError("gains: {task: 2000}\n" + m, "task * step must be < 1");
  expectError("colision: {}\n" + m, "sim.yaml:1: field 'colision': unknown key");
  expectError("mannequins: []\n", "no mannequin");
  expectError("stepper: dynamic\n" + m, "sim.yaml:1: field 'stepper': expected controller or kinematic");
  expectError("joint_limits: {activation: -1}\n" + m, "field 'joint_limits.activation': -1 is outside [0, 1]");
  expectError("target_twist: {max_speed: nan}\n" + m, "field 'target_twist.max_speed': 'nan' is not a finite number");
  // a missing controller config is named at its entry (paths are resolved when the config is read)
  try {
    simservice::buildMannequins(simservice::parseSimConfig(core::ConfigNode::parse(
        "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, controller: configs/control/nope.yaml, "
        "control_frames: {hand_l: hand_l}}\n", "s")));
    ADD_FAILURE() << "no error for a missing controller config";
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("s:2: field 'mannequins[0].controller'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nope.yaml"), std::string::npos) << e.what();
  }
  const auto c = simservice::loadSimConfig("configs/sim/sim_demo.yaml");
  EXPECT_EQ(c.mannequins.size(), 1u);
  EXPECT_EQ(c.mannequins[0].frames.size(), 6u);
  EXPECT_THROW(simservice::buildMannequins(simservice::parseSimConfig(core::ConfigNode::parse(
                   "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, control_frames: {wing: x}}\n", "s"))),
               core::ConfigError);
}

namespace {
// One mocap publisher of a replay run: its name (Header.source of its frames) and its frames.
struct MocapFeed {
  std::string name;
  std::vector<v1::MocapFrame> frames;
  std::vector<std::pair<std::size_t, v1::Trigger>> triggers = {};  // (k, trigger): published just before frame k
};

// Runs a replay-mode sim service in-process with `cfg` (publish/connect set here), one publisher per
// feed on its own endpoint (the service connects to all of them), publishes every feed's frames and
// returns the sim.world payloads once the sim has counted every frame delivered.
// `lockstep`: frame k of every feed is published only once the sim has stepped through every frame
// before it (the sim's heartbeats, every 10 ms, count them). Without it, the frames of several feeds
// (several sockets) reach the sim in whatever order the sockets deliver them: all of one feed's first,
// possibly, and then the other source's mannequin waits uncalibrated while the first one's actor moves.
std::vector<std::string> replayRun(simservice::SimServiceConfig cfg, const std::vector<MocapFeed>& feeds, const std::string& dir,
                                   bool lockstep = false, std::vector<std::string>* scenario_states = nullptr) {
  zmq::context_t ctx;
  const std::string sim_ep = "ipc://" + dir + "/sim";
  // the recorded input is byte-identical between runs: no wall-clock send time in it either
  std::vector<std::unique_ptr<transport::Publisher>> mocap;
  std::vector<std::string> eps;
  for (const MocapFeed& f : feeds) {
    eps.push_back("ipc://" + dir + "/" + f.name);
    mocap.push_back(std::make_unique<transport::Publisher>(ctx, transport::PublisherOptions{f.name, {eps.back()}, 100000, true}));
  }
  cfg.mode = simservice::Mode::kReplay;
  cfg.world.interpolation_delay = 0;
  cfg.publish = {sim_ep};
  if (cfg.mocap_sources.empty()) cfg.connect = eps;  // else each source names its endpoint
  simservice::SimService sim(cfg, ctx, lockstep ? 0.01 : 0.5);
  transport::Subscriber out(ctx, {"test", {sim_ep}});
  std::vector<std::string> worlds;
  out.subscribeRaw("sim.world", [&](std::string_view, std::string_view payload, const transport::Received&) {
    worlds.emplace_back(payload);
  });
  if (scenario_states != nullptr)
    out.subscribeRaw("scenario.state", [&](std::string_view, std::string_view payload, const transport::Received&) {
      scenario_states->emplace_back(payload);
    });
  std::atomic<bool> stop{false};
  std::thread runner([&] { sim.run(stop); });
  // Every wait has a deadline and fails naming what it waited for; the sim is stopped in every case.
  // 1. both subscriptions in place: ours on the sim (its heartbeats reach us), the sim's on every mocap
  //    publisher (mocap.frame and collision.contacts of the sim's socket have reached it)
  // 2. the frames published, then the sim's heartbeats until one counts every frame delivered: in
  //    replay mode the frames a poll delivers are stepped through before the next heartbeat, and the
  //    worlds published before that heartbeat reach us before it (one publisher socket)
  std::uint64_t delivered = 0;
  bool heartbeat = false;
  out.subscribe(transport::topics::kHeartbeat, std::function<void(const v1::Heartbeat&)>([&](const v1::Heartbeat& hb) {
                  heartbeat = true;
                  for (const auto& t : hb.topics())
                    if (t.topic() == transport::topics::kMocapFrame.name && !t.published()) delivered = t.messages();
                }));
  auto waitFor = [&](auto cond, const char* what) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!cond()) {
      if (std::chrono::steady_clock::now() >= until) {
        ADD_FAILURE() << "replayRun: no " << what << " within 60 s";
        return false;
      }
      out.poll(std::chrono::milliseconds(5));
      for (auto& m : mocap) m->poll();
    }
    return true;
  };
  std::size_t total = 0;
  for (const MocapFeed& f : feeds) total += f.frames.size();
  const auto subscribed = [&] {
    for (auto& m : mocap)
      if (m->subscriptions() < 2) return false;
    return true;
  };
  if (waitFor([&] { return heartbeat; }, "heartbeat of the sim") &&
      waitFor(subscribed, "subscription of the sim to mocap.frame and collision.contacts of every publisher")) {
    // interleaved by index, as two live systems would send them
    std::uint64_t sent = 0;
    for (std::size_t k = 0;; ++k) {
      bool any = false;
      for (std::size_t i = 0; i < feeds.size(); ++i)
        if (k < feeds[i].frames.size()) {
          for (const auto& [at, trigger] : feeds[i].triggers)
            if (at == k) {
              v1::Trigger t = trigger;
              mocap[i]->publish(transport::topics::kScenarioTrigger, t);
            }
          v1::MocapFrame f = feeds[i].frames[k];  // publish() fills the header
          mocap[i]->publish(transport::topics::kMocapFrame, f);
          ++sent;
          any = true;
        }
      if (!any) break;
      if (lockstep && !waitFor([&] { return delivered >= sent; }, "heartbeat counting the frames of one index delivered")) break;
    }
    waitFor([&] { return delivered >= total; }, "heartbeat counting every mocap frame delivered");
    EXPECT_EQ(delivered, total);
  }
  stop = true;
  runner.join();
  return worlds;
}

// Runs the demo config (no collision service) on `frames` from one publisher "mocap".
std::vector<std::string> replayOnce(const std::vector<v1::MocapFrame>& frames, const std::string& dir, std::size_t expected) {
  simservice::SimServiceConfig cfg = simservice::loadSimConfig("configs/sim/sim_demo.yaml");
  cfg.collision.mode = simservice::CollisionMode::kNone;  // no collision service in this test
  const auto worlds = replayRun(cfg, {{"mocap", frames}}, dir);
  EXPECT_EQ(worlds.size(), expected);
  return worlds;
}

// A standing actor's 7 bodies at `k`/120 s (capture clock `offset_ns` + k/120 s), `at` the pelvis
// position: pelvis swaying, hands rising 1.2 m/s for 20 frames, then everything held still.
v1::MocapFrame actorFrame(int k, const math::Vector3& at = math::Vector3::Zero(), std::int64_t offset_ns = 0) {
  v1::MocapFrame f;
  f.mutable_header()->set_stamp_ns(offset_ns + static_cast<std::int64_t>(std::llround(k / 120.0 * 1e9)));
  f.set_frame_number(static_cast<std::uint64_t>(k));
  const char* names[] = {"pelvis", "thorax", "head", "hand_l", "hand_r", "foot_l", "foot_r"};
  const math::Vector3 rel[] = {{0, 0, 0.95}, {0, 0, 1.3}, {0, 0, 1.65}, {0.1, 0.3, 0.9}, {0.1, -0.3, 0.9}, {0, 0.1, 0.08}, {0, -0.1, 0.08}};
  for (int b = 0; b < 7; ++b) {
    v1::RigidBody* rb = f.add_bodies();
    rb->set_name(names[b]);
    rb->set_tracked(true);
    rb->set_quality(1);
    const math::Vector3 p = at + rel[b] + math::Vector3(0.02 * std::sin(std::min(k, 20) * 0.3), 0, b >= 3 && b <= 4 ? 0.01 * std::min(k, 20) : 0.0);
    transport::toMsg(pose(p), *rb->mutable_pose());
  }
  return f;
}
}  // namespace

TEST(SimService, ReplayModeIsDeterministicByteForByte) {
  // a BVH-like stream of 20 frames at 120 Hz (pelvis swaying, hands moving)
  std::vector<v1::MocapFrame> frames;
  for (int k = 0; k < 20; ++k) frames.push_back(actorFrame(k));
  const mannequin::testutil::TempDir tmp("mq-sim");  // removed after the test, however it ends
  const std::string dir = tmp.path().string();
  const auto a = replayOnce(frames, dir, 9);
  const auto b = replayOnce(frames, dir, 9);
  // 19 intervals of 1/120 s = 158 steps of 1 ms → sim.world at 60 Hz: 9 states
  ASSERT_EQ(a.size(), 9u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i] == b[i]) << "sim.world " << i << " differs";
  v1::WorldState w;
  ASSERT_TRUE(w.ParseFromString(a.back()));
  EXPECT_EQ(w.header().send_time_ns(), 0);
  EXPECT_EQ(w.mode(), "replay");
  EXPECT_TRUE(w.mannequins(0).calibrated());
  EXPECT_EQ(w.mannequins(0).q_size(), 43);
  EXPECT_EQ(w.mannequins(0).control_frames_size(), 6);
  EXPECT_EQ(w.mocap().frame_number(), 18u);  // the 9th state is at 150 ms = frame 18's capture time
}

TEST(SimService, WorldStateCarriesTheSceneObjectsAtRestOnTheTable) {
  // the demo config on configs/scenes/table.yaml: the ball and the tray (movable, with a mass) start
  // touching the table top (z = 0.75 m) and stay there; the tool has no mass (a static body)
  simservice::SimServiceConfig cfg = simservice::loadSimConfig("configs/sim/sim_demo.yaml");
  cfg.collision.mode = simservice::CollisionMode::kNone;
  cfg.world.physics.scene = collision::loadScene("configs/scenes/table.yaml");
  std::vector<v1::MocapFrame> frames;
  for (int k = 0; k < 60; ++k) frames.push_back(actorFrame(k));  // 0.49 s
  const mannequin::testutil::TempDir tmp("mq-sim");  // removed after the test, however it ends
  const std::string dir = tmp.path().string();
  const auto worlds = replayRun(cfg, {{"mocap", frames}}, dir);
  ASSERT_GE(worlds.size(), 20u);
  for (const std::size_t i : {std::size_t{0}, worlds.size() - 1}) {
    v1::WorldState w;
    ASSERT_TRUE(w.ParseFromString(worlds[i]));
    ASSERT_EQ(w.objects_size(), 2) << w.ShortDebugString();
    // rest heights from the scene file: ball centre = table top + radius (no margins);
    // tray centre = table top + its margin (2 mm shells) + half its 5 mm bottom
    struct Expected {
      const char* name;
      math::Vector3 p;
    } expected[] = {{"ball", {0.9, 0.2, 0.75 + 0.11}}, {"tray", {1.15, -0.15, 0.75 + 0.002 + 0.0025}}};
    for (const Expected& e : expected) {
      const v1::ObjectState* o = nullptr;
      for (const auto& obj : w.objects())
        if (obj.name() == e.name) o = &obj;
      ASSERT_NE(o, nullptr) << e.name << " missing in sim.world " << i;
      const math::SE3 H = transport::fromMsg(o->pose());
      // contacts hold the objects within the contact layer's penetration tolerance (mm), nothing slides
      EXPECT_NEAR(H.p.z(), e.p.z(), 2e-3) << e.name << " in sim.world " << i;
      EXPECT_LT((H.p - e.p).head<2>().norm(), 1e-3) << e.name << " in sim.world " << i;
      EXPECT_LT(math::logSO3(H.R).norm(), 1e-3) << e.name;
      EXPECT_FALSE(o->hinged());
      ASSERT_EQ(o->twist_size(), 6);
      EXPECT_LT(std::hypot(o->velocity().x(), o->velocity().y(), o->velocity().z()), 0.01) << e.name << " at rest";
    }
  }
}

TEST(SimConfig, MocapSourcesAreValidated) {
  auto expectError = [](const std::string& yaml, const std::string& what) {
    try {
      simservice::parseSimConfig(core::ConfigNode::parse(yaml, "sim.yaml"));
      ADD_FAILURE() << "no error for\n" << yaml;
    } catch (const core::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << "got: " << e.what();
    }
  };
  const std::string sources = "mocap_sources:\n  - {name: mocap_a, connect: ipc:///tmp/a}\n  - {name: mocap_b}\n";
  const std::string m = "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, control_frames: {hand_l: hand_l},\n"
                        "     mocap_source: ";
  expectError(sources + m + "mocap_c}\n",
              "sim.yaml:6: field 'mannequins[0].mocap_source': unknown mocap source 'mocap_c' (mocap_sources: mocap_a, mocap_b)");
  expectError(m + "mocap_a}\n", "sim.yaml:3: field 'mannequins[0].mocap_source': unknown mocap source 'mocap_a' (no mocap_sources listed)");
  expectError("mocap_sources:\n  - {name: x}\n  - {name: x}\n" + m + "x}\n", "sim.yaml:3: field 'mocap_sources[1].name': mocap source 'x' listed twice");
  expectError("mocap_sources:\n  - {name: x, conect: y}\n" + m + "x}\n", "sim.yaml:2: field 'mocap_sources[0].conect': unknown key");
  const auto c = simservice::parseSimConfig(core::ConfigNode::parse(sources + m + "mocap_b}\n", "sim.yaml"));
  ASSERT_EQ(c.mocap_sources.size(), 2u);
  EXPECT_EQ(c.mocap_sources[0].connect, std::vector<std::string>{"ipc:///tmp/a"});
  EXPECT_TRUE(c.mocap_sources[1].connect.empty());
  EXPECT_EQ(c.mannequins[0].mocap_source, "mocap_b");
  EXPECT_EQ(simservice::buildMannequins(c)[0].mocap_source, "mocap_b");
}

// Offline (mannequin-simulate), each `mocap_sources` entry with its own `mocap` plays its own capture: two
// scripted actors 2 m apart drive two mannequins, each ending where its own capture stands (with one capture
// for every source both would stand in one place); a missing capture names the sim config's line, a bad one
// its own line, and --mocap (the main capture) is refused when no mannequin plays it.
TEST(SimOffline, EachMocapSourcePlaysItsOwnCapture) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("mannequin_offline_sources_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto actor = [&](const std::string& file, double x, double yb) {
    std::ofstream(dir / file) << "name: mocap\nsource: synthetic\nsynthetic:\n  rate_hz: 120\n  duration: 0.5\n  bodies:\n"
                              << "    - {name: pelvis, waypoints: [{t: 0, xyz: [" << x << ", 0, 0.932]}, {t: 0.4, xyz: [" << x << ", " << yb
                              << ", 0.932]}]}\n"
                              << "    - {name: head, center: [" << x << ", 0, 1.469]}\n"
                              << "    - {name: foot_l, center: [" << x << ", 0.094, 0.068]}\n"
                              << "    - {name: foot_r, center: [" << x << ", -0.094, 0.068]}\n";
  };
  actor("a.yaml", -1.0, 0.0);
  actor("b.yaml", 1.0, 0.05);
  const auto write = [&](const std::string& source_a) {
    std::ofstream(dir / "sim.yaml")
        << "name: sim\nstep: 0.001\nmocap_sources:\n  - {name: sa, mocap: " << source_a << "}\n"
        << "  - {name: sb, mocap: " << (dir / "b.yaml").string() << "}\n"
        << "mannequins:\n"
        << "  - {name: a, mocap_source: sa, config: configs/mannequins/male_50th.yaml,\n"
        << "     control_frames: {pelvis: pelvis, head: head, foot_l: foot_l, foot_r: foot_r}}\n"
        << "  - {name: b, mocap_source: sb, config: configs/mannequins/male_50th.yaml,\n"
        << "     control_frames: {pelvis: pelvis, head: head, foot_l: foot_l, foot_r: foot_r}}\n";
  };
  write((dir / "a.yaml").string());
  simservice::OfflineOptions o;
  o.config = (dir / "sim.yaml").string();
  {
    simservice::OfflineRun run(o);
    EXPECT_EQ(run.config().mocap_sources[1].mocap, (dir / "b.yaml").string());
    EXPECT_NEAR(run.captureLength(), 0.5, 1e-12);  // the clock: the first mannequin's capture
    const simservice::OfflineSummary s = run.run();
    const sim::World& w = run.world();
    const auto pelvis = [&](int m) { return w.data(m).oMf[static_cast<std::size_t>(w.model(m).frameIndex("pelvis"))].p; };
    std::printf("own captures: %lld frames, %.3f s; pelvis a (%.4f, %.4f), b (%.4f, %.4f)\n", s.frames, s.sim_time_s,
                pelvis(0).x(), pelvis(0).y(), pelvis(1).x(), pelvis(1).y());
    EXPECT_EQ(s.nan_steps, 0);
    EXPECT_NEAR(s.sim_time_s, 0.5, 0.01);
    EXPECT_GE(s.frames, 2 * 60);  // both captures' frames fed (120 Hz, 0.5 s each)
    EXPECT_NEAR(pelvis(0).x(), -1.0, 0.02);
    EXPECT_NEAR(pelvis(1).x(), 1.0, 0.02);
    EXPECT_NEAR(pelvis(0).y(), 0.0, 0.01);
    EXPECT_NEAR(pelvis(1).y(), 0.05, 0.01);  // b's own waypoints moved it 5 cm
  }
  const auto expectError = [&](const std::string& what, const simservice::OfflineOptions& opts) {
    try {
      simservice::OfflineRun run(opts);
      ADD_FAILURE() << "no error, expected " << what;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << "got: " << e.what();
    }
  };
  write((dir / "missing.yaml").string());
  expectError((dir / "sim.yaml").string() + ":4: field 'mocap_sources[0].mocap'", o);
  std::ofstream(dir / "bad.yaml") << "name: mocap\nsource: synthetic\nsynthetic:\n  rate_hz: 120\n  bodies:\n    - {name: pelvis}\n";
  write((dir / "bad.yaml").string());
  expectError((dir / "bad.yaml").string() + ":4: field 'synthetic.duration'", o);  // a scripted capture without an end
  std::ofstream(dir / "bad.yaml") << "name: mocap\nsource: synthetic\nsynthetic:\n  duration: 1\n  bodies:\n    - {name: pelvis, waypoints: 3}\n";
  expectError((dir / "bad.yaml").string() + ":6", o);
  write((dir / "a.yaml").string());
  simservice::OfflineOptions with_mocap = o;
  with_mocap.mocap = "data/bvh/cmu_max_131_03.bvh";
  expectError("no mannequin plays the main capture", with_mocap);
  fs::remove_all(dir);
}

// Offline, the loads in the hands feed RULA's force/load and REBA's load scores: the waiter (configs/sim/
// sim_waiter.yaml) lifts a 0.8 kg tray and pushes a door. At every scored sample the assessment the run
// hands out is the one of the posture with, per side, the load |World::handForces| / 9.80665 kg; a hand
// force of 73.55 N is 7.5 kg (RULA force/load 1, REBA load 1); the tray and the door do load the hands
// (some samples at 2 kg or more) and change some scores against the posture alone.
TEST(SimOffline, HandLoadsFromGraspsAndContactsFeedRulaAndReba) {
  EXPECT_NEAR(simservice::handLoadKg(math::Vector3(0, 0, -73.549875)), 7.5, 1e-9);
  ergonomics::TaskInput load;
  load.load_kg = 7.5;
  EXPECT_EQ(ergonomics::rulaForceLoad(load), 1);
  EXPECT_EQ(ergonomics::rebaLoad(load), 1);

  simservice::OfflineOptions o;
  o.config = "configs/sim/sim_waiter.yaml";
  simservice::OfflineRun run(o);
  ergonomics::Evaluator eval(run.world().model(0));
  long long scored = 0, loaded = 0, changed = 0;
  double max_load = 0;
  const simservice::OfflineSummary s = run.run([&](const World& w, const std::vector<const ergonomics::Assessment*>& a) {
    if (a.empty() || a[0] == nullptr) return;
    ++scored;
    const auto hands = w.handForces(0);
    const ergonomics::PostureAngles angles = eval.measure(w.q(0));
    bool any_load = false;
    for (const ergonomics::Side side : {ergonomics::Side::kLeft, ergonomics::Side::kRight}) {
      const auto k = static_cast<std::size_t>(side);
      ergonomics::TaskInput in;
      in.load_kg = hands[k].norm() / 9.80665;
      max_load = std::max(max_load, in.load_kg);
      any_load = any_load || in.load_kg >= 2.0;
      const ergonomics::RulaSide rula = ergonomics::scoreRula(angles, side, in);
      const ergonomics::RebaSide reba = ergonomics::scoreReba(angles, side, in);
      EXPECT_EQ(a[0]->rula[k].force_load, rula.force_load) << w.time();
      EXPECT_EQ(a[0]->rula[k].grand, rula.grand) << w.time();
      EXPECT_EQ(a[0]->reba[k].load, reba.load) << w.time();
      EXPECT_EQ(a[0]->reba[k].score, reba.score) << w.time();
      const ergonomics::RulaSide bare = ergonomics::scoreRula(angles, side, {});
      if (bare.grand != rula.grand) ++changed;
    }
    if (any_load) ++loaded;
  });
  const simservice::ErgonomicsSummary& e = s.ergonomics.front();
  std::printf("waiter: %lld scored samples, %lld with a hand load >= 2 kg, %lld side scores changed by the load; "
              "largest load %.2f kg; hand force mean / max left %.1f / %.1f N, right %.1f / %.1f N\n",
              scored, loaded, changed, max_load, e.meanHandForce(0), e.hand_force_max_n[0], e.meanHandForce(1), e.hand_force_max_n[1]);
  EXPECT_EQ(e.samples, scored);
  EXPECT_EQ(e.hand_force_samples, scored);
  EXPECT_NEAR(std::max(e.hand_load_max_kg[0], e.hand_load_max_kg[1]), max_load, 1e-9);
  EXPECT_GT(loaded, 0);
  EXPECT_GT(changed, 0);
}

TEST(SimService, TwoMocapSourcesDriveTwoMannequins) {
  // two capture systems (two mocap services "mocap_a" and "mocap_b", each with its own clock: b's
  // starts at 1000 s) with the same body names; actor a stands at the origin, actor b 3 m away. The
  // two feeds go in lockstep, as two live systems running at once would send them (replayRun)
  const mannequin::testutil::TempDir tmp("mq-sim");  // removed after the test, however it ends
  const std::string dir = tmp.path().string();
  const std::string yaml = "step: 0.001\nworld_rate: 60\nstepper: controller\n"
                           "physics: {enabled: true, scene: configs/scenes/floor.yaml}\n"
                           "mocap_sources:\n"
                           "  - {name: mocap_a, connect: ipc://" + dir + "/mocap_a}\n"
                           "  - {name: mocap_b, connect: ipc://" + dir + "/mocap_b}\n"
                           "mannequins:\n"
                           "  - {name: a, config: configs/mannequins/male_50th.yaml, mocap_source: mocap_a,\n"
                           "     control_frames: {pelvis: pelvis, hand_l: hand_l, hand_r: hand_r, foot_l: foot_l, foot_r: foot_r}}\n"
                           "  - {name: b, config: configs/mannequins/male_50th.yaml, mocap_source: mocap_b,\n"
                           "     control_frames: {pelvis: pelvis, hand_l: hand_l, hand_r: hand_r, foot_l: foot_l, foot_r: foot_r}}\n";
  const simservice::SimServiceConfig cfg = simservice::parseSimConfig(core::ConfigNode::parse(yaml, "two.yaml"));
  const math::Vector3 at_b(3, 0, 0);
  const std::int64_t clock_b = 1'000'000'000'000;
  MocapFeed a{"mocap_a", {}}, b{"mocap_b", {}};
  for (int k = 0; k < 80; ++k) {  // the actors move, then hold still for 0.5 s (the last world: both at rest)
    a.frames.push_back(actorFrame(k));
    b.frames.push_back(actorFrame(k, at_b, clock_b));
  }
  const auto worlds = replayRun(cfg, {a, b}, dir, /*lockstep=*/true);
  ASSERT_FALSE(worlds.empty());
  v1::WorldState w;
  ASSERT_TRUE(w.ParseFromString(worlds.back()));
  ASSERT_EQ(w.mannequins_size(), 2);
  // each mannequin calibrated under its own actor: a at the origin, b 3 m along x (had b taken a's
  // frames, or the reverse, the two would stand at the same place)
  for (int i = 0; i < 2; ++i) {
    const v1::MannequinState& m = w.mannequins(i);
    ASSERT_TRUE(m.calibrated()) << m.name();
    const math::Vector3 expect = i == 0 ? math::Vector3::Zero() : at_b;
    EXPECT_LT(std::hypot(m.q(0) - expect.x(), m.q(1) - expect.y()), 0.05) << m.name() << " root at " << m.q(0) << ", " << m.q(1);
    for (const auto& cf : m.control_frames())
      if (cf.frame() == "pelvis" || cf.frame().rfind("foot_", 0) == 0) {
        EXPECT_LT(cf.position_error(), 0.05) << m.name() << " " << cf.frame();
      }
  }
  // the same motion relative to each actor, each in its own clock, is tracked the same way (the hands'
  // 20 cm rise from hanging arms is not fully reached by either: what matters is that they agree)
  ASSERT_EQ(w.mannequins(0).control_frames_size(), w.mannequins(1).control_frames_size());
  for (int k = 0; k < w.mannequins(0).control_frames_size(); ++k)
    EXPECT_NEAR(w.mannequins(0).control_frames(k).position_error(), w.mannequins(1).control_frames(k).position_error(), 0.005)
        << w.mannequins(0).control_frames(k).frame();
  // the newest frame of each source, tagged with its source and in its own capture clock
  ASSERT_EQ(w.mocap_sources_size(), 2) << w.ShortDebugString();
  EXPECT_EQ(w.mocap_sources(0).source(), "mocap_a");
  EXPECT_EQ(w.mocap_sources(1).source(), "mocap_b");
  EXPECT_LT(w.mocap_sources(0).stamp_ns(), 1'000'000'000);
  EXPECT_GE(w.mocap_sources(1).stamp_ns(), clock_b);
  EXPECT_EQ(w.mocap().source(), "mocap_a");  // no frame of the default source: the first named one's
}

// The sim service runs its config's scenario (key `scenario`) in the loop: an operator trigger from the
// network (scenario.trigger, on a publisher the sim connects to) switches the right hand from the capture
// to an autonomous reach; sim.world reports each control frame's mode; scenario.state reports the state.
TEST(SimService, ATriggerOnTheNetworkSwitchesTheScenarioAndTheWorldReportsTheModes) {
  const mannequin::testutil::TempDir tmp("mq-sim");  // removed after the test, however it ends
  const std::string dir = tmp.path().string();
  const std::string sc_path = dir + "/reach.yaml";
  {
    std::ofstream f(sc_path);
    f << "scenario: reach\nmannequins:\n  - {name: operator, frames: [hand_r]}\ntriggers: [go]\ninitial: follow\n"
         "states:\n  - name: follow\n    transitions: [{to: reach, name: operator says go, when: {trigger: go}}]\n"
         "  - name: reach\n    modes:\n      hand_r: {mode: autonomous, goal: {xyz: [0.5, -0.3, 1.2], rpy_deg: [0, 0, 0]}, duration_s: 0.05}\n";
  }
  simservice::SimServiceConfig cfg = simservice::parseSimConfig(core::ConfigNode::parse(
      "mannequins:\n  - {name: operator, config: configs/mannequins/male_50th.yaml, control_frames: {pelvis: pelvis, head: head, "
      "hand_l: hand_l, hand_r: hand_r, foot_l: foot_l, foot_r: foot_r}}\nworld_rate: 120\nscenario: {file: " + sc_path +
      ", state_rate: 100}\n", "sim.yaml"));
  EXPECT_EQ(cfg.scenario.scenario.name, "reach");
  MocapFeed feed{"mocap", {}, {}};
  for (int k = 0; k < 40; ++k) feed.frames.push_back(actorFrame(k));
  v1::Trigger go;
  go.set_name("go");
  v1::Trigger typo;
  typo.set_name("og");  // not declared: logged, ignored
  feed.triggers = {{10, typo}, {20, go}};
  std::vector<std::string> states;
  const auto worlds = replayRun(cfg, {feed}, dir, true, &states);
  ASSERT_FALSE(worlds.empty());
  // the right hand's mode: free until the trigger's frame (k = 20 → 0.167 s), autonomous after
  double first_autonomous = -1, last_free = -1;
  for (const std::string& p : worlds) {
    v1::WorldState w;
    ASSERT_TRUE(w.ParseFromString(p));
    for (const v1::ControlFrameState& c : w.mannequins(0).control_frames()) {
      if (c.frame() == "hand_r" && c.mode() == "autonomous" && first_autonomous < 0) first_autonomous = w.sim_time();
      if (c.frame() == "hand_r" && c.mode() == "free") last_free = w.sim_time();
      if (c.frame() != "hand_r") {
        EXPECT_EQ(c.mode(), "free") << c.frame();
      }
    }
  }
  EXPECT_GT(first_autonomous, 19.0 / 120.0 - 1e-9);
  EXPECT_LT(first_autonomous, 21.0 / 120.0 + 0.01);
  EXPECT_LT(last_free, first_autonomous);
  // scenario.state: 'follow' then 'reach' with the transition's label
  ASSERT_FALSE(states.empty());
  v1::ScenarioState first, last;
  ASSERT_TRUE(first.ParseFromString(states.front()));
  ASSERT_TRUE(last.ParseFromString(states.back()));
  EXPECT_EQ(first.scenario(), "reach");
  EXPECT_EQ(first.state(), "follow");
  EXPECT_EQ(last.state(), "reach");
  ASSERT_EQ(last.last_events_size(), 1);
  EXPECT_EQ(last.last_events(0), "operator says go");
}

TEST(SimConfig, ScenarioErrorsNameTheFileLineAndWhat) {
  const std::string m = "mannequins:\n  - {name: operator, config: configs/mannequins/male_50th.yaml, control_frames: {hand_l: hand_l}}\n";
  const auto expectError = [&](const std::string& yaml, const std::string& what) {
    try {
      const auto c = simservice::parseSimConfig(core::ConfigNode::parse(yaml + m, "sim.yaml"));
      sim::World w(simservice::buildMannequins(c), c.world);
      simservice::setupScenario(w, c);
      ADD_FAILURE() << "no error for\n" << yaml;
    } catch (const core::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << "got: " << e.what();
    }
  };
  expectError("scenario: configs/scenarios/nope.yaml\n", "sim.yaml:1: field 'scenario'");
  expectError("scenario: {file: configs/scenarios/drill.yaml, triggers: [{at: 1, name: guidance}]}\n",
              "trigger 'guidance' is not declared by scenario 'drill'");
  expectError("scenario: {file: configs/scenarios/drill.yaml, triggers: [{at: 2, name: guide}, {at: 1, name: abort}]}\n",
              "triggers must be listed in time order");
  expectError("scenario: {file: configs/scenarios/drill.yaml, triggers: [{at: -1, name: guide}]}\n", "field 'scenario.triggers[0].at'");
  expectError("scenario: {file: configs/scenarios/drill.yaml, trigers: []}\n", "unknown key");
  // the World lacks what the scenario names: the drill scenario's mannequin 'worker'
  expectError("scenario: configs/scenarios/drill.yaml\n", "no mannequin 'worker'");
}

// mannequin-trigger, the operator's trigger on a live deployment (docs/scenario.md): it binds its endpoint,
// waits until a subscriber to scenario.trigger connects (as the sim does), sends the trigger once and
// exits 0; with nobody subscribing it exits 1 after --wait, saying so; a trigger the sim would refuse is a
// bad command line (exit 2) naming why.
TEST(TriggerTool, SendsOnceToASubscriberAndRefusesBadTriggers) {
  namespace fs = std::filesystem;
  const fs::path tool = testutil::binDir() / "mannequin-trigger";
  ASSERT_TRUE(fs::exists(tool)) << tool;
  const mannequin::testutil::TempDir tmp("mq-sim");  // removed after the test, however it ends
  const std::string dir = tmp.path().string();
  const std::string endpoint = "ipc://" + dir + "/trigger";
  testutil::Child child({tool.string(), "go", "--value", "3", "--publish", endpoint, "--wait", "30"}, dir + "/trigger.log");
  ASSERT_TRUE(child.started());
  zmq::context_t context(1);
  transport::SubscriberOptions so;
  so.name = "sim";
  transport::Subscriber sub(context, so);
  std::vector<v1::Trigger> got;
  sub.subscribe(transport::topics::kScenarioTrigger, [&](const v1::Trigger& t) { got.push_back(t); });
  // the tool may not have bound yet: ZeroMQ connects to an ipc endpoint once it exists
  sub.connect(endpoint);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (got.empty() && std::chrono::steady_clock::now() < deadline) sub.poll(std::chrono::milliseconds(50));
  ASSERT_EQ(got.size(), 1u) << "no trigger within 30 s";
  EXPECT_EQ(got[0].name(), "go");
  EXPECT_EQ(got[0].value(), "3");
  EXPECT_EQ(got[0].header().source(), "trigger");
  EXPECT_EQ(child.wait(std::chrono::seconds(30)), 0);
  // sent once: nothing more arrives (the tool has exited)
  sub.poll(std::chrono::milliseconds(100));
  EXPECT_EQ(got.size(), 1u);
  // nobody subscribes: exit 1 after --wait
  const testutil::ToolResult none = testutil::runTool(tool.string() + " go --publish ipc://" + dir + "/nobody --wait 0.3", 30);
  EXPECT_EQ(none.exit_code, 1) << none.err;
  EXPECT_NE(none.err.find("nobody subscribed to scenario.trigger"), std::string::npos) << none.err;
  // a name the sim refuses (over 128 characters): a bad command line, before anything is bound
  const testutil::ToolResult bad = testutil::runTool(tool.string() + " " + std::string(200, 'x') + " --wait 0.3", 30);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("at most 128"), std::string::npos) << bad.err;
}

// mannequin-sim --scenario replaces the config's `scenario` (the jump's deployment runs the shipped demo config
// with configs/scenarios/jump.yaml so): the ball scenario on the ball config starts; the same option naming the
// jump scenario (mannequin 'operator') on the ball config (mannequin 'player') is refused naming both (a bad
// config: exit 1, docs/cluster.md) — the scenario the World got is the option's, not the config's; a missing
// file is a bad command line (exit 2).
TEST(SimTool, ScenarioOptionReplacesTheConfigsScenario) {
  namespace fs = std::filesystem;
  const fs::path tool = testutil::binDir() / "mannequin-sim";
  ASSERT_TRUE(fs::exists(tool)) << tool;
  const mannequin::testutil::TempDir tmp("mq-sim");  // removed after the test, however it ends
  const std::string dir = tmp.path().string();
  const std::string common = tool.string() + " --config configs/sim/sim_ball.yaml --publish ipc://" + dir + "/sim --connect ipc://" + dir +
                             "/mocap --duration 0.3";
  const testutil::ToolResult same = testutil::runTool(common + " --scenario configs/scenarios/ball.yaml", 60);
  EXPECT_EQ(same.exit_code, 0) << same.err;
  const testutil::ToolResult other = testutil::runTool(common + " --scenario configs/scenarios/jump.yaml", 60);
  EXPECT_EQ(other.exit_code, 1) << other.err;
  EXPECT_NE(other.err.find("jump"), std::string::npos) << other.err;
  EXPECT_NE(other.err.find("operator"), std::string::npos) << other.err;
  const testutil::ToolResult missing = testutil::runTool(common + " --scenario configs/scenarios/nonexistent.yaml", 60);
  EXPECT_EQ(missing.exit_code, 2) << missing.err;
  EXPECT_NE(missing.err.find("nonexistent.yaml"), std::string::npos) << missing.err;
  // --io-threads (a service's ZeroMQ I/O threads): 2 runs; 0 is a bad command line naming the option
  const testutil::ToolResult two = testutil::runTool(common + " --io-threads 2", 60);
  EXPECT_EQ(two.exit_code, 0) << two.err;
  const testutil::ToolResult zero = testutil::runTool(common + " --io-threads 0", 60);
  EXPECT_EQ(zero.exit_code, 2) << zero.err;
  EXPECT_NE(zero.err.find("--io-threads"), std::string::npos) << zero.err;
}

// Offline from a recording (--mocap F.mcap, as mannequin-batch takes it): the ball demonstration's scripted
// capture written as mocap.frame messages into an MCAP file (as mannequin-record writes them) replays the
// same run as the script itself: the same frames at the same capture times give the same states in the same
// order and the ball where the script put it. Not bit for bit: a body's orientation crosses the message as a
// quaternion (round-off of 1e-16), which 9000 steps of contacts grow to micrometres (4e-8 to 5e-6 m, depending
// on the factorisations' round-off), and an event whose value crosses its threshold slowly moves with it — the
// wrist ending its approach to the put pose at ≈ 1 mm/s enters the 3 cm sphere a few ms apart (7 steps seen).
// So: each state within 20 steps (20 ms) of the script's, the ball within 1 mm. A recording without mocap.frame,
// one with a NaN sample and a missing file are refused naming the file (and the message).
TEST(SimOffline, ARecordedCapturePlaysLikeTheScriptItRecorded) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("mannequin_offline_mcap_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // the script's frames, as the mocap service streams them
  YAML::Node raw = YAML::LoadFile("configs/sim/mocap_ball.yaml");
  raw["synthetic"]["paced"] = false;
  const std::unique_ptr<mocap::Source> script = mocap::makeSource(core::ConfigNode(raw, "configs/sim/mocap_ball.yaml"));
  std::vector<mocap::Frame> frames;
  while (!script->finished())
    if (auto f = script->next(std::chrono::microseconds(0))) frames.push_back(*f);
  ASSERT_GT(frames.size(), 1000u);
  const auto record = [&](const fs::path& path, bool with_nan) {
    recording::McapWriter w(path.string());
    const auto schema = w.addSchema("mannequin.v1.MocapFrame", "protobuf", proto::fileDescriptorSet(v1::MocapFrame::descriptor()));
    const auto ch = w.addChannel(std::string(transport::topics::kMocapFrame.name), schema, "protobuf");
    for (std::size_t i = 0; i < frames.size(); ++i) {
      v1::MocapFrame msg;
      transport::toMsg(frames[i], "synthetic", msg);
      msg.mutable_header()->set_source("mocap");
      if (with_nan && i == 7) msg.mutable_bodies(0)->mutable_pose()->mutable_position()->set_x(std::nan(""));
      std::string payload;
      msg.SerializeToString(&payload);
      const auto t = static_cast<recording::Timestamp>(frames[i].stamp_ns);
      w.write(ch, static_cast<std::uint32_t>(i + 1), t, t, payload);
    }
    w.close();
  };
  const fs::path good = dir / "ball_capture.mcap";
  record(good, false);
  const auto runOf = [&](const std::string& mocap, std::vector<std::string>& states, math::Vector3& ball) {
    simservice::OfflineOptions o;
    o.config = "configs/sim/sim_ball.yaml";
    o.mocap = mocap;
    simservice::OfflineRun run(o);
    std::string last;
    const simservice::OfflineSummary s = run.run({}, [&](const sim::World& w, double) {
      const scenario::Engine* e = w.scenarioEngine();
      if (e != nullptr && e->state() >= 0 && e->stateName() != last) {
        last = e->stateName();
        states.push_back(last + "@" + std::to_string(w.stepCount()));
      }
    });
    ball = run.world().object(run.world().findObject("ball")).pose().p;
    return s;
  };
  std::vector<std::string> scripted_states, recorded_states;
  math::Vector3 scripted_ball, recorded_ball;
  const simservice::OfflineSummary a = runOf("", scripted_states, scripted_ball);
  const simservice::OfflineSummary b = runOf(good.string(), recorded_states, recorded_ball);
  std::printf("scripted: %lld frames, %lld steps, ball (%.4f %.4f %.4f); recorded: %lld frames, %lld steps, ball (%.4f %.4f %.4f)\n", a.frames,
              a.steps, scripted_ball.x(), scripted_ball.y(), scripted_ball.z(), b.frames, b.steps, recorded_ball.x(), recorded_ball.y(),
              recorded_ball.z());
  EXPECT_EQ(b.frames, a.frames);
  EXPECT_EQ(b.steps, a.steps);
  ASSERT_EQ(scripted_states.size(), 7u);
  ASSERT_EQ(recorded_states.size(), scripted_states.size()) << "recorded states differ from the script's";
  for (std::size_t i = 0; i < scripted_states.size(); ++i) {
    const auto at = scripted_states[i].find('@'), rat = recorded_states[i].find('@');
    ASSERT_NE(at, std::string::npos);
    ASSERT_NE(rat, std::string::npos);
    EXPECT_EQ(recorded_states[i].substr(0, rat), scripted_states[i].substr(0, at)) << "state " << i;
    EXPECT_LE(std::abs(std::stol(recorded_states[i].substr(rat + 1)) - std::stol(scripted_states[i].substr(at + 1))), 20)
        << recorded_states[i] << " vs " << scripted_states[i];
  }
  EXPECT_LT((recorded_ball - scripted_ball).norm(), 1e-3);
  EXPECT_GT(recorded_ball.x(), 0.70);  // kicked past the table's front edge, as the script does
  // bad recordings
  const auto refused = [&](const std::string& mocap, const std::string& what) {
    try {
      std::vector<std::string> st;
      math::Vector3 p;
      runOf(mocap, st, p);
      ADD_FAILURE() << mocap << ": accepted";
    } catch (const simservice::OfflineInputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  const fs::path nan = dir / "nan.mcap";
  record(nan, true);
  refused(nan.string(), nan.string() + ": mocap.frame message 7");
  const fs::path empty = dir / "world_only.mcap";
  {
    recording::McapWriter w(empty.string());
    const auto schema = w.addSchema("mannequin.v1.WorldState", "protobuf", proto::fileDescriptorSet(v1::WorldState::descriptor()));
    w.addChannel("sim.world", schema, "protobuf");
    w.close();
  }
  refused(empty.string(), empty.string() + ": no mocap.frame messages (its topics: sim.world)");
  refused((dir / "missing.mcap").string(), (dir / "missing.mcap").string());
  fs::remove_all(dir);
}
