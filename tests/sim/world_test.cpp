// libs/sim in-process: the mocap buffer (interpolation, hold, occlusion), and the World's calibration onto
// control frames, tracking, occlusion policy and set-up checks.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "mannequin/math/so3.hpp"
#include "mannequin/mocap/source.hpp"
#include "mannequin/sim/mocap_buffer.hpp"
#include "mannequin/sim/world.hpp"
#include "../common/mannequins.hpp"
#include "../common/pose.hpp"
#include "actor.hpp"

using namespace mannequin;
using namespace mannequin::sim;

namespace world_test {
using mannequin::testing::pose;

mocap::Frame frame(std::int64_t stamp_ns, std::vector<mocap::Body> bodies) {
  mocap::Frame f;
  f.stamp_ns = stamp_ns;
  f.sequence = static_cast<std::uint64_t>(stamp_ns / 1000000 + 1);
  f.bodies = std::move(bodies);
  return f;
}

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
  World w(mannequin::testing::pelvisAndLeftHandOperator(), cfg);
  EXPECT_FALSE(w.calibrated(0));
  // the actor stands 2 m away, turned 90° about z; the hand body is 10 cm off the mannequin's hand
  const math::SE3 pelvis = pose({2, 1, 0.95}, {0, 0, std::numbers::pi / 2});
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
  World w(mannequin::testing::pelvisAndLeftHandOperator(), cfg);
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
  auto m = mannequin::testing::pelvisAndLeftHandOperator();
  m[0].frames.push_back({"tail", "tail"});
  EXPECT_THROW(World(std::move(m), SimConfig{}), std::invalid_argument);
}

}  // namespace world_test
