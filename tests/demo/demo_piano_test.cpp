// Demonstration 3, Fig. 4.11 (thesis 4.3.1): two mannequins, each driven by its own actor (its own mocap
// source, configs/sim/sim_piano.yaml), lift a piano by its handles with four control frames, one on each
// hand, carry it and put it down (configs/scenarios/piano.yaml, configs/scenes/piano.yaml). The claim:
// while carried the piano never touches the floor, and it travels at least 1 m.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mannequin/math/so3.hpp"
#include "mannequin/scenario/engine.hpp"
#include "mannequin/simservice/offline.hpp"
#include "timeline.hpp"

using namespace mannequin;

namespace {

/// The lowest point of the piano's body (a 0.5 × 1.2 × 1.0 m box centred on its origin, configs/scenes/piano.yaml).
double lowestPoint(const math::SE3& pose) {
  double z = 1e9;
  for (const int sx : {-1, 1})
    for (const int sy : {-1, 1})
      for (const int sz : {-1, 1}) z = std::min(z, pose.act(math::Vector3(0.25 * sx, 0.6 * sy, 0.5 * sz)).z());
  return z;
}

}  // namespace

TEST(Demo, Fig411TwoMannequinsCarryAPianoItNeverTouchesTheFloorAndTravelsOverOneMetre) {
  simservice::OfflineOptions o;
  o.config = "configs/sim/sim_piano.yaml";
  simservice::OfflineRun run(o);
  ASSERT_EQ(run.world().numMannequins(), 2);
  const char* const hands[] = {"hand_l", "hand_r"};
  demo_test::Timeline timeline;
  int piano = -1, piano_body = -1, floor_body = -1;
  math::SE3 at_grasp, at_release;
  std::array<math::SE3, 4> grip0;  // each hand's pose in the piano's frame at the grasp
  double lowest_carried = 1e9, worst_slip = 0, worst_turn = 0;
  long carried_steps = 0, carried_floor_contacts = 0;
  bool grasped = false, released = false;
  const auto handInPiano = [&](const sim::World& w, int m, const char* h) {
    const math::SE3& oMh = w.data(m).oMf[static_cast<std::size_t>(w.model(m).frameIndex(h))];
    return oMh.inverse() * w.object(piano).pose();
  };
  const simservice::OfflineSummary s = run.run({}, [&](const sim::World& w, double) {
    if (piano < 0) {
      piano = w.findObject("piano");
      piano_body = w.collisionWorld()->findBody("scene/piano");
      floor_body = w.collisionWorld()->findBody("scene/floor");
    }
    const scenario::Engine* e = w.scenarioEngine();
    timeline.see(e, w.time());
    if (e == nullptr || e->state() < 0) return;
    const std::string& st = e->stateName();
    if (st == "grasped" && !grasped) {  // the step the four grasps were made
      grasped = true;
      at_grasp = w.object(piano).pose();
      for (int m = 0, i = 0; m < 2; ++m)
        for (const char* h : hands) grip0[static_cast<std::size_t>(i++)] = handInPiano(w, m, h);
    }
    if (st == "released" && !released) {
      released = true;
      at_release = w.object(piano).pose();
    }
    if (grasped && !released)  // held: no hand slides or turns on its handle
      for (int m = 0, i = 0; m < 2; ++m)
        for (const char* h : hands) {
          const math::SE3 d = grip0[static_cast<std::size_t>(i++)].inverse() * handInPiano(w, m, h);
          worst_slip = std::max(worst_slip, d.p.norm());
          worst_turn = std::max(worst_turn, math::logSO3(d.R).norm());
        }
    if (st != "carried") return;
    ++carried_steps;
    lowest_carried = std::min(lowest_carried, lowestPoint(w.object(piano).pose()));
    for (const sim::ContactReport& c : w.contacts())
      if ((c.body_a == piano_body && c.body_b == floor_body) || (c.body_a == floor_body && c.body_b == piano_body))
        ++carried_floor_contacts;
  });
  ASSERT_GE(piano, 0);
  ASSERT_GE(piano_body, 0);
  ASSERT_GE(floor_body, 0);
  const math::Vector3 moved = at_release.p - at_grasp.p;
  const double travel = std::hypot(moved.x(), moved.y());
  std::printf("piano: %s| carried %ld steps, its lowest point %.4f m above the floor, %ld piano-floor contact rows; "
              "travelled %.4f m (x %.4f, y %.4f), put down %.4f m from where it was grasped in z; worst hand slip "
              "%.2e m / %.2e rad; NaN steps %lld, unapplied actions %lld, %.1f s wall\n",
              timeline.str().c_str(), carried_steps, lowest_carried, carried_floor_contacts, travel, moved.x(), moved.y(),
              moved.z(), worst_slip, worst_turn, s.nan_steps, static_cast<long long>(s.scenario_unapplied_actions), s.wall_s);
  EXPECT_EQ(timeline.states(), (std::vector<std::string>{"reach", "grasped", "carried", "set_down", "released"})) << timeline.str();
  EXPECT_GE(carried_steps, 1000);                 // carried for more than a second
  EXPECT_GT(lowest_carried, 0.02);                // never touches the floor: above the contact activation distance
  EXPECT_EQ(carried_floor_contacts, 0);
  EXPECT_GE(travel, 1.0);                         // carried at least 1 m
  EXPECT_LT(std::abs(moved.z()), 0.01);           // and put down on the floor again
  EXPECT_LT(worst_slip, 0.01);                    // no hand slides on its handle
  EXPECT_LT(worst_turn, 0.05);
  EXPECT_EQ(s.scenario_unapplied_actions, 0);
  EXPECT_EQ(s.nan_steps, 0);
}
