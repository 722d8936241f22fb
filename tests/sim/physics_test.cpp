// sim::World with PhysicsConfig on: weight, floor contacts, the calibration clearance (4.4.3) and the
// shipped CMU hop with gravity (soles never below the floor beyond the margin, zero NaN, standing after
// landing).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "mannequin/collision/scene.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/mocap/source.hpp"
#include "mannequin/sim/controller_stepper.hpp"
#include "mannequin/sim/world.hpp"
#include "../constraints/male50_fixture.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

using namespace mannequin;
using namespace mannequin::sim;

namespace {
using mannequin::testing_fixture::male50;

SimConfig physicsConfig(const std::string& scene = "configs/scenes/floor.yaml") {
  SimConfig c;
  c.physics.enabled = true;
  c.physics.scene = collision::loadScene(scene);
  return c;
}

MannequinSetup operatorSetup(double gravity) {
  MannequinSetup m;
  m.name = "operator";
  m.model = male50();
  for (const char* b : {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r"}) m.frames.push_back({b, b});
  m.controller = control::loadControllerConfig("configs/control/mocap.yaml");
  m.controller->gravity = math::Vector3(0, 0, gravity);
  return m;
}

// A static actor: every body where the standing mannequin's frames are, sunk `sink` m (an actor whose
// markers sit lower than the model's frames: the paradox of 4.4.3).
mocap::Frame standingActor(const World& w, std::int64_t stamp_ns, double sink) {
  mocap::Frame f;
  f.stamp_ns = stamp_ns;
  f.sequence = static_cast<std::uint64_t>(stamp_ns / 1000000 + 1);
  const skeleton::Model& model = w.model(0);
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, skeleton::standingConfiguration(model));
  for (const char* b : {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r"}) {
    math::SE3 T = d.oMf[static_cast<std::size_t>(model.frameIndex(b))];
    T.p.z() -= sink;
    f.bodies.push_back({b, T, true});
  }
  return f;
}
}  // namespace

TEST(Physics, TheMannequinStandsOnTheFloorUnderItsWeight) {
  std::vector<MannequinSetup> setups;
  setups.push_back(operatorSetup(-9.81));
  World w(std::move(setups), physicsConfig());
  ASSERT_TRUE(w.physics());
  ASSERT_NE(w.collisionWorld(), nullptr);
  // the actor's markers are 3 cm lower than the model's frames: without the calibration clearance
  // the foot targets would be 3 cm inside the floor
  w.addMocap(standingActor(w, 0, 0.03));
  w.anchor(0);
  ASSERT_TRUE(w.calibrated(0));
  const double margin = w.config().physics.segment_margin;
  double lowest = 1e9;
  int foot_steps = 0;
  const int steps = 2000;
  for (int k = 0; k < steps; ++k) {
    if (k % 10 == 0) w.addMocap(standingActor(w, static_cast<std::int64_t>(k) * 1'000'000 + 1, 0.03));
    ASSERT_TRUE(w.step()) << "step " << k;
    const MannequinDiagnostics& md = w.mannequinDiagnostics(0);
    lowest = std::min(lowest, md.sole_height_m);
    foot_steps += md.foot_contact ? 1 : 0;
    const auto& rep = w.diagnostics().solver;
    ASSERT_FALSE(rep.fallback) << "step " << k << ": Lemke " << lcp::statusName(rep.lemke_status) << ", "
                               << constraints::solverUsedName(rep.solver) << ", " << rep.rows << " rows, LCP size "
                               << rep.lcp_size << ", " << rep.pivots << " pivots";
  }
  std::printf("standing 2 s: lowest sole %.5f m, foot contact in %d/%d steps, %d contacts (%d active), max penetration %.5f m\n",
              lowest, foot_steps, steps, w.diagnostics().contacts, w.diagnostics().active_contacts,
              w.diagnostics().max_penetration_m);
  EXPECT_GE(lowest, -margin);               // never below the floor beyond the margin
  EXPECT_EQ(foot_steps, steps);             // both feet rest on the floor the whole time
  EXPECT_GT(w.diagnostics().active_contacts, 0);
  EXPECT_EQ(w.failedSteps(), 0u);
  // the soles carry weight: the floor's normal forces are positive and bounded by the weight plus the
  // couplings' pull (they cannot exceed what gravity and the springs push with)
  double total = 0;
  for (const ContactReport& c : w.contacts()) total += c.normal_force;
  EXPECT_GT(total, 0.0);
}

namespace {
struct HopRun {
  long steps = 0;
  double lowest_sole = 1e9;
  double max_penetration = 0;
  long below_margin = 0;
  long foot_steps = 0;
  long fallbacks = 0;
  std::uint64_t failed = 0;
  bool standing_at_end = false;
  double mean_hand = 0;
};

// The shipped CMU capture (131_03: start, hop, stop), as the replay mode steps it.
HopRun runHop(bool physics) {
  YAML::Node raw = YAML::LoadFile("configs/sim/mocap_demo.yaml");
  raw["bvh"]["paced"] = false;
  raw["bvh"]["loop"] = false;
  auto source = mocap::makeSource(core::ConfigNode(raw, "configs/sim/mocap_demo.yaml"));
  std::vector<MannequinSetup> setups;
  setups.push_back(operatorSetup(physics ? -9.81 : 0.0));
  SimConfig cfg = physics ? physicsConfig() : SimConfig{};
  World w(std::move(setups), cfg);
  HopRun r;
  while (!source->finished()) {
    const auto s = source->next(std::chrono::microseconds(0));
    if (!s) continue;
    w.addMocap(*s);
    if (!w.anchored()) w.anchor(s->stamp_ns);
    while (w.captureTimeNs() < s->stamp_ns) {
      w.step();
      ++r.steps;
      if (!physics) continue;
      const MannequinDiagnostics& md = w.mannequinDiagnostics(0);
      r.lowest_sole = std::min(r.lowest_sole, md.sole_height_m);
      r.below_margin += md.sole_height_m < -w.config().physics.segment_margin ? 1 : 0;
      r.foot_steps += md.foot_contact ? 1 : 0;
      r.max_penetration = std::max(r.max_penetration, w.diagnostics().max_penetration_m);
      r.fallbacks += w.diagnostics().solver.fallback ? 1 : 0;
      r.mean_hand += w.controlFrames(0)[2].position_error;
    }
  }
  r.failed = w.failedSteps();
  if (physics) r.standing_at_end = w.mannequinDiagnostics(0).foot_contact;
  r.mean_hand /= static_cast<double>(std::max(r.steps, 1L));
  return r;
}
}  // namespace

TEST(Physics, TheCmuHopWithGravityKeepsTheSolesOnTheFloorAndLandsStanding) {
  const HopRun r = runHop(true);
  std::printf("CMU 131_03 with gravity: %ld steps, lowest sole %.5f m, %ld steps below the margin, max penetration "
              "%.5f m, a foot on the floor in %.1f%% of the steps, %ld fallbacks, mean left-hand error %.4f m, standing "
              "at the end: %s\n",
              r.steps, r.lowest_sole, r.below_margin, r.max_penetration,
              100.0 * static_cast<double>(r.foot_steps) / static_cast<double>(r.steps), r.fallbacks, r.mean_hand,
              r.standing_at_end ? "yes" : "no");
  ASSERT_GT(r.steps, 2000);
  EXPECT_EQ(r.failed, 0u);                       // zero NaN steps
  EXPECT_EQ(r.below_margin, 0);                  // the soles never go below the floor beyond the margin
  EXPECT_LE(r.max_penetration, 0.005);           // the real geometry penetrates less than the margin
  EXPECT_TRUE(r.standing_at_end);                // after the hop, on its feet again
  EXPECT_GT(r.foot_steps, r.steps / 2);          // most of the capture stands (the hop is short)
}
