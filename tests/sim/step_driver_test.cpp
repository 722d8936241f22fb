// libs/sim's StepDriver (the session loop of the live service and the offline run), RateDivider and
// RunTotals, on a World stepped by the kinematic tracker.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mannequin/sim/run_totals.hpp"
#include "mannequin/sim/step_driver.hpp"
#include "mannequin/sim/world.hpp"
#include "../common/mannequins.hpp"
#include "../common/pose.hpp"
#include "actor.hpp"

using namespace mannequin;
using namespace mannequin::sim;
using mannequin::testing::pose;

namespace {

mocap::Frame frameAt(std::int64_t stamp_ns, double hand_x) {
  mocap::Frame f;
  f.stamp_ns = stamp_ns;
  f.sequence = static_cast<std::uint64_t>(stamp_ns / 1000000 + 1);
  f.bodies = {{"pelvis", pose({0, 0, 0.95}), true}, {"hand_l", pose({hand_x, 0.2, 0.9}), true}};
  return f;
}

}  // namespace

TEST(StepDriver, StepsToEachFramesCaptureTimeWithTheHooksAroundEveryStep) {
  SimConfig cfg;  // δt = 1 ms
  World world(mannequin::testing::pelvisAndLeftHandOperator(), cfg);
  StepDriver driver(world);
  int before = 0, after = 0;
  bool after_saw_step = true;
  driver.setHooks({{},
                   [&] { ++before; },
                   [&](bool ok) {
                     ++after;
                     EXPECT_TRUE(ok);
                     after_saw_step = after_saw_step && world.stepCount() == static_cast<std::uint64_t>(after);
                   }});
  // the first frame anchors the clock: no step yet (the World is at the frame's capture time)
  const StepDriver::Added first = driver.addFrame(frameAt(5'000'000, 0.3), "");
  EXPECT_TRUE(first.taken);
  EXPECT_TRUE(first.anchored);
  EXPECT_TRUE(world.calibrated(0));
  EXPECT_EQ(driver.stepTo(5'000'000, ""), 0);
  // 10 ms later: 10 steps of 1 ms, each with both hooks, the last one ending at the frame's time
  EXPECT_FALSE(driver.addFrame(frameAt(15'000'000, 0.31), "").anchored);
  EXPECT_EQ(driver.stepTo(15'000'000, ""), 10);
  EXPECT_EQ(world.stepCount(), 10u);
  EXPECT_EQ(world.captureTimeNs(""), 15'000'000);
  EXPECT_EQ(before, 10);
  EXPECT_EQ(after, 10);
  EXPECT_TRUE(after_saw_step);
  // a step that would pass the frame's time is left for the next frame
  driver.addFrame(frameAt(15'500'000, 0.31), "");
  EXPECT_EQ(driver.stepTo(15'500'000, ""), 0);
  EXPECT_FALSE(driver.due(15'500'000, ""));
  EXPECT_TRUE(driver.due(16'000'000, ""));
  // a duplicate frame is not taken (World::addMocap)
  EXPECT_FALSE(driver.addFrame(frameAt(15'500'000, 0.31), "").taken);
}

TEST(StepDriver, ProceedStopsTheStepsAndAFarDriftReanchorsTheSourceClock) {
  SimConfig cfg;
  World world(mannequin::testing::pelvisAndLeftHandOperator(), cfg);
  StepDriver driver(world);
  long allowed = 4;
  driver.setHooks({[&] { return allowed-- > 0; }, {}, {}});
  driver.addFrame(frameAt(0, 0.3), "");
  driver.addFrame(frameAt(100'000'000, 0.3), "");
  EXPECT_EQ(driver.stepTo(100'000'000, ""), 4);  // proceed said no after four steps
  EXPECT_EQ(world.stepCount(), 4u);
  // a frame 2 s ahead of the source's clock: within a 5 s threshold it is taken as is, past a 1 s one
  // the clock is anchored again at it
  const StepDriver::Added kept = driver.addFrame(frameAt(2'004'000'000, 0.3), "", 5.0);
  EXPECT_FALSE(kept.reanchored);
  EXPECT_NEAR(kept.drift_s, 2.0, 1e-9);
  const StepDriver::Added moved = driver.addFrame(frameAt(2'005'000'000, 0.3), "", 1.0);
  EXPECT_TRUE(moved.reanchored);
  EXPECT_NEAR(moved.drift_s, 2.001, 1e-9);
  EXPECT_EQ(world.captureTimeNs(""), 2'005'000'000);
}

TEST(RateDivider, TicksAtTheExactAverageRate) {
  RateDivider every(60.0, 0.001);  // 60 Hz out of 1 kHz steps: not a whole number of steps
  int ticks = 0;
  for (int k = 0; k < 10000; ++k) ticks += every.tick() ? 1 : 0;
  EXPECT_EQ(ticks, 600);  // 10 s at 60 Hz
  RateDivider all(1000.0, 0.001);
  for (int k = 0; k < 100; ++k) EXPECT_TRUE(all.tick());
}

TEST(RunTotals, AddsTrackingErrorsOfTheCalibratedHandsAndCountsSteps) {
  SimConfig cfg;
  World world(mannequin::testing::pelvisAndLeftHandOperator(), cfg);
  RunTotals totals;
  totals.reset(world.numMannequins());
  EXPECT_TRUE(std::isnan(totals.meanHandError()));
  EXPECT_EQ(totals.min_balance_per_mannequin_m.size(), 1u);
  world.addMocap(frameAt(0, 0.3));
  world.anchor(0);
  world.addMocap(frameAt(100'000'000, 0.4));  // the hand body moves 10 cm in 100 ms
  double error_sum = 0;
  for (int k = 0; k < 20; ++k) {
    const bool ok = world.step();
    totals.add(world, ok);
    error_sum += world.controlFrames(0)[1].position_error;
  }
  EXPECT_EQ(totals.steps, 20);
  EXPECT_EQ(totals.nan_steps, 0);
  EXPECT_EQ(totals.hand_samples, 20);
  EXPECT_EQ(totals.foot_samples, 0);  // no foot frame driven
  EXPECT_NEAR(totals.meanHandError(), error_sum / 20, 1e-15);
  EXPECT_GT(totals.meanHandError(), 0.0);
  EXPECT_EQ(totals.max_contacts, 0);  // physics off: no contacts, no balance distance
  EXPECT_TRUE(std::isnan(totals.min_balance_distance_m));
}
