// libs/sim (mocap buffer, calibration, tracking, occlusion policy) and the sim service in replay mode
// (deterministic bytes) and live mode over ipc.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <thread>

#include "mannequin/math/so3.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/simservice/messages.hpp"
#include "mannequin/simservice/sim_service.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/subscriber.hpp"

using namespace mannequin;
using namespace mannequin::sim;

namespace {
math::SE3 pose(const math::Vector3& p, const math::Vector3& r = math::Vector3::Zero()) {
  math::SE3 H;
  H.R = math::expSO3(r);
  H.p = p;
  return H;
}

mocap::Frame frame(std::int64_t stamp_ns, std::vector<mocap::Body> bodies) {
  mocap::Frame f;
  f.stamp_ns = stamp_ns;
  f.sequence = static_cast<std::uint64_t>(stamp_ns / 1000000 + 1);
  f.bodies = std::move(bodies);
  return f;
}

std::vector<MannequinSetup> oneMannequin() {
  MannequinSetup s;
  s.name = "operator";
  s.model = skeleton::buildMannequin(skeleton::loadMannequinSpec("configs/mannequins/male_50th.yaml"));
  s.frames = {{"pelvis", "pelvis"}, {"hand_l", "hand_l"}};
  return {std::move(s)};
}

std::string tempDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto p = std::filesystem::temp_directory_path() / ("mq-sim-" + std::string(info->name()) + "-" + std::to_string(getpid()));
  std::filesystem::create_directories(p);
  return p.string();
}
}  // namespace

TEST(MocapBuffer, InterpolatesHoldsAndReportsOcclusion) {
  MocapBuffer buf;
  EXPECT_TRUE(buf.add(frame(0, {{"a", pose({0, 0, 0}), true}})));
  EXPECT_TRUE(buf.add(frame(10'000'000, {{"a", pose({1, 0, 0}, {0, 0, 0.2}), true}})));
  EXPECT_FALSE(buf.add(frame(10'000'000, {})));  // not newer
  const BodySample mid = buf.sample("a", 2'500'000);
  EXPECT_TRUE(mid.tracked);
  EXPECT_LT((mid.pose.p - math::Vector3(0.25, 0, 0)).norm(), 1e-12);
  EXPECT_LT((math::logSO3(mid.pose.R) - math::Vector3(0, 0, 0.05)).norm(), 1e-12);
  EXPECT_LT((buf.sample("a", 50'000'000).pose.p - math::Vector3(1, 0, 0)).norm(), 1e-12);  // held
  buf.add(frame(20'000'000, {{"a", pose({5, 5, 5}), false}}));
  const BodySample occluded = buf.sample("a", 25'000'000);
  EXPECT_FALSE(occluded.tracked);
  EXPECT_TRUE(occluded.ever_tracked);
  EXPECT_EQ(occluded.last_tracked_ns, 10'000'000);
  EXPECT_LT((occluded.pose.p - math::Vector3(1, 0, 0)).norm(), 1e-12);  // last tracked pose, not the garbage
  EXPECT_FALSE(buf.sample("nobody", 0).ever_tracked);
}

TEST(World, CalibratesOntoControlFramesAndTracksAMovedBody) {
  SimConfig cfg;
  World w(oneMannequin(), cfg);
  EXPECT_FALSE(w.calibrated(0));
  // the actor stands 2 m away, turned 90° about z; the hand body is 10 cm off the mannequin's hand
  const math::SE3 pelvis = pose({2, 1, 0.95}, {0, 0, M_PI / 2});
  const math::SE3 hand = pose({2.3, 1.2, 0.9});
  w.addMocap(frame(0, {{"pelvis", pelvis, true}, {"hand_l", pose({0, 0, 0}), false}}));
  EXPECT_FALSE(w.calibrated(0));  // a body is untracked: wait
  w.addMocap(frame(1'000'000, {{"pelvis", pelvis, true}, {"hand_l", hand, true}}));
  ASSERT_TRUE(w.calibrated(0));
  w.anchor(1'000'000);
  // calibrated: the mannequin stands under the actor's pelvis, facing its heading, zero error
  EXPECT_NEAR(w.q(0)(0), 2.0, 1e-12);
  EXPECT_NEAR(w.q(0)(1), 1.0, 1e-12);
  w.step();
  for (const auto& st : w.controlFrames(0)) {
    EXPECT_LT(st.position_error, 1e-6) << st.frame;
    EXPECT_LT(st.orientation_error, 1e-6) << st.frame;
  }
  // the hand body moves 5 cm up: the mannequin's hand follows (first order, 1/task ≈ 25 ms)
  const math::SE3 up = pose(hand.p + math::Vector3(0, 0, 0.05));
  w.addMocap(frame(2'000'000, {{"pelvis", pelvis, true}, {"hand_l", up, true}}));
  const math::Vector3 before = w.controlFrames(0)[1].actual.p;
  for (int k = 0; k < 300; ++k) w.step();
  const auto& h = w.controlFrames(0)[1];
  EXPECT_LT(h.position_error, 2e-3);
  EXPECT_NEAR(h.actual.p.z() - before.z(), 0.05, 2e-3);
  EXPECT_EQ(w.stepCount(), 301u);
  EXPECT_NEAR(w.time(), 0.301, 1e-12);
}

TEST(World, OcclusionHoldsThenBlendsToPostureThenComesBackWithoutJump) {
  SimConfig cfg;
  cfg.occlusion_hold = 0.1;
  cfg.occlusion_blend = 0.2;
  World w(oneMannequin(), cfg);
  const math::SE3 pelvis = pose({0, 0, 0.95});
  const math::SE3 hand = pose({0.3, 0.3, 1.1});  // hand raised
  w.addMocap(frame(0, {{"pelvis", pelvis, true}, {"hand_l", hand, true}}));
  w.anchor(0);
  const math::Vector3 raised = w.controlFrames(0)[1].target.p;
  w.addMocap(frame(1'000'000, {{"pelvis", pelvis, true}, {"hand_l", hand, false}}));  // occluded from 1 ms on
  for (int k = 0; k < 100; ++k) w.step();  // t = 0.1 s: still holding
  EXPECT_DOUBLE_EQ(w.controlFrames(0)[1].weight, 1.0);
  EXPECT_LT((w.controlFrames(0)[1].target.p - raised).norm(), 1e-12);
  EXPECT_FALSE(w.controlFrames(0)[1].tracked);
  for (int k = 0; k < 100; ++k) w.step();  // t = 0.2 s: half-way through the blend
  EXPECT_NEAR(w.controlFrames(0)[1].weight, 0.5, 0.02);
  for (int k = 0; k < 150; ++k) w.step();  // t = 0.35 s: blended out
  EXPECT_EQ(w.controlFrames(0)[1].weight, 0.0);
  // back in sight: the weight ramps up at 1/blend per second, no jump of the target weight
  w.addMocap(frame(360'000'000, {{"pelvis", pelvis, true}, {"hand_l", hand, true}}));
  for (int k = 0; k < 20; ++k) w.step();
  EXPECT_GT(w.controlFrames(0)[1].weight, 0.0);
  EXPECT_LT(w.controlFrames(0)[1].weight, 0.2);
  EXPECT_TRUE(w.controlFrames(0)[1].tracked);
}

TEST(World, RejectsUnknownFrames) {
  auto m = oneMannequin();
  m[0].frames.push_back({"tail", "tail"});
  EXPECT_THROW(World(std::move(m), SimConfig{}), std::invalid_argument);
}

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
  // a missing controller config is named with the mannequin
  try {
    simservice::buildMannequins(simservice::parseSimConfig(core::ConfigNode::parse(
        "mannequins:\n  - {name: a, config: configs/mannequins/male_50th.yaml, controller: configs/control/nope.yaml, "
        "control_frames: {hand_l: hand_l}}\n", "s")));
    ADD_FAILURE() << "no error for a missing controller config";
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("mannequin 'a': controller:"), std::string::npos) << e.what();
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
// Runs a replay-mode sim service in-process, feeds it `frames`, returns the sim.world payloads.
std::vector<std::string> replayOnce(const std::vector<v1::MocapFrame>& frames, const std::string& dir, std::size_t expected) {
  zmq::context_t ctx;
  const std::string mocap_ep = "ipc://" + dir + "/mocap", sim_ep = "ipc://" + dir + "/sim";
  // the recorded input is byte-identical between runs: no wall-clock send time in it either
  transport::Publisher mocap(ctx, {"mocap", {mocap_ep}, 1000, true});
  simservice::SimServiceConfig cfg = simservice::loadSimConfig("configs/sim/sim_demo.yaml");
  cfg.mode = simservice::Mode::kReplay;
  cfg.world.interpolation_delay = 0;
  cfg.collision.mode = simservice::CollisionMode::kNone;  // no collision service in this test
  cfg.publish = {sim_ep};
  cfg.connect = {mocap_ep};
  simservice::SimService sim(cfg, ctx);
  transport::Subscriber out(ctx, {"test", {sim_ep}});
  std::vector<std::string> worlds;
  out.subscribeRaw("sim.world", [&](std::string_view, std::string_view payload, const transport::Received&) {
    worlds.emplace_back(payload);
  });
  std::atomic<bool> stop{false};
  std::thread runner([&] { sim.run(stop); });
  // Every wait has a deadline and fails naming what it waited for; the sim is stopped in every case.
  // 1. both subscriptions in place: ours on the sim (its heartbeats reach us), the sim's on the mocap
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
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!cond()) {
      if (std::chrono::steady_clock::now() >= until) {
        ADD_FAILURE() << "replayOnce: no " << what << " within 20 s";
        return false;
      }
      out.poll(std::chrono::milliseconds(5));
      mocap.poll();
    }
    return true;
  };
  if (waitFor([&] { return heartbeat; }, "heartbeat of the sim") &&
      waitFor([&] { return mocap.subscriptions() >= 2; }, "subscription of the sim to mocap.frame and collision.contacts")) {
    for (v1::MocapFrame f : frames) mocap.publish(transport::topics::kMocapFrame, f);
    waitFor([&] { return delivered >= frames.size(); }, "heartbeat counting every mocap frame delivered");
    EXPECT_EQ(delivered, frames.size());
  }
  stop = true;
  runner.join();
  EXPECT_EQ(worlds.size(), expected);
  return worlds;
}
}  // namespace

TEST(SimService, ReplayModeIsDeterministicByteForByte) {
  // a BVH-like stream of 20 frames at 120 Hz (pelvis swaying, hands moving)
  std::vector<v1::MocapFrame> frames;
  for (int k = 0; k < 20; ++k) {
    v1::MocapFrame f;
    f.mutable_header()->set_stamp_ns(static_cast<std::int64_t>(std::llround(k / 120.0 * 1e9)));
    f.set_frame_number(k);
    const char* names[] = {"pelvis", "thorax", "head", "hand_l", "hand_r", "foot_l", "foot_r"};
    const math::Vector3 at[] = {{0, 0, 0.95}, {0, 0, 1.3}, {0, 0, 1.65}, {0.1, 0.3, 0.9}, {0.1, -0.3, 0.9}, {0, 0.1, 0.08}, {0, -0.1, 0.08}};
    for (int b = 0; b < 7; ++b) {
      v1::RigidBody* rb = f.add_bodies();
      rb->set_name(names[b]);
      rb->set_tracked(true);
      rb->set_quality(1);
      const math::Vector3 p = at[b] + math::Vector3(0.02 * std::sin(k * 0.3), 0, b >= 3 && b <= 4 ? 0.01 * k : 0.0);
      transport::toMsg(pose(p), *rb->mutable_pose());
    }
    frames.push_back(f);
  }
  const std::string dir = tempDir();
  const auto a = replayOnce(frames, dir, 9);
  const auto b = replayOnce(frames, dir, 9);
  std::filesystem::remove_all(dir);
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
