// The thesis's demonstrations (4.3.1, Fig. 4.8–4.16) as shipped scenario + scene + capture, run the way
// `mannequin-simulate --scenario` runs them (simservice::OfflineRun), each asserting its figure's claim.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mannequin/scenario/engine.hpp"
#include "mannequin/simservice/offline.hpp"
#include "timeline.hpp"

using namespace mannequin;

using demo_test::Timeline;

// Demonstration 1, Fig. 4.8: a jump with six control frames (feet, hands, pelvis, head all free, the
// CMU capture 131_03). The scenario names the phases from the floor's push on the feet; the claim: both
// feet leave the floor and land, and the soles never sink below the floor beyond the segments' margin.
TEST(Demo, Fig48JumpWithSixControlFramesBothFeetLeaveTheFloorAndLandWithoutPenetration) {
  simservice::OfflineOptions o;
  o.config = "configs/sim/sim_demo.yaml";
  o.scenario = "configs/scenarios/jump.yaml";
  simservice::OfflineRun run(o);
  Timeline timeline;
  double lowest_sole = 1e9, margin = -1, w_step = 0;
  long airborne_steps = 0, airborne_feet_touching = 0, flight = 0, longest_flight = 0;
  bool standing_at_end = false;
  double standing_ankle = 0;  // the highest foot control frame over the first 0.5 s standing
  const simservice::OfflineSummary s = run.run({}, [&](const sim::World& w, double) {
    margin = w.config().physics.segment_margin;
    w_step = w.config().step;
    const scenario::Engine* e = w.scenarioEngine();
    ASSERT_NE(e, nullptr);
    const sim::MannequinDiagnostics& d = w.mannequinDiagnostics(0);
    timeline.see(e, w.time());
    if (e->state() >= 0) {
      if (e->stateName() == "standing" && e->timeInState() < 0.5)
        for (const sim::DrivenFrame& f : w.controlFrames(0))
          if (f.frame == "foot_l" || f.frame == "foot_r") standing_ankle = std::max(standing_ankle, f.actual.p.z());
      if (e->stateName() == "airborne") {
        ++airborne_steps;
        airborne_feet_touching += d.foot_contact ? 1 : 0;
        flight = d.foot_contact ? 0 : flight + 1;  // steps in a row with no foot within touching distance of the floor
        longest_flight = std::max(longest_flight, flight);
      }
    }
    if (w.calibrated(0)) lowest_sole = std::min(lowest_sole, d.sole_height_m);
    standing_at_end = d.foot_contact;
  });
  std::printf("jump: %s| airborne %ld steps (a foot within touching distance in %ld, longest flight %ld steps), lowest sole "
              "%.4f m (margin %.3f), NaN steps %lld, ankles standing at most %.3f m\n",
              timeline.str().c_str(), airborne_steps, airborne_feet_touching, longest_flight, lowest_sole, margin, s.nan_steps, standing_ankle);
  EXPECT_EQ(timeline.states(), (std::vector<std::string>{"standing", "airborne", "landed"})) << timeline.str();
  // a flight, not a contact flicker: more than 0.1 s with neither foot within touching distance of the floor
  // (foot_contact_tolerance; the scenario's 'landed' waits for 50 N, so the last steps before it may touch)
  EXPECT_GT(static_cast<double>(longest_flight) * w_step, 0.1);
  EXPECT_GE(lowest_sole, -margin);               // no penetration beyond the margin, take-off and landing included
  EXPECT_EQ(s.nan_steps, 0);
  // the scenario's 14 cm zone is above the ankles of the standing mannequin (else it would say nothing)
  EXPECT_LT(standing_ankle, 0.14);
  EXPECT_TRUE(standing_at_end);                  // landed on its feet
  EXPECT_EQ(s.scenario, "jump");
  EXPECT_EQ(s.scenario_state, "landed");
}

// Demonstration 4, Fig. 4.12: drilling with a drill in the right hand and a torch in the left, each
// guided by its own virtual mechanism (configs/sim/sim_drill.yaml). The claims, while guided (after the
// 0.5 s blend onto the mechanisms): the drill's axis stays within 1° of the hole's axis, and the torch's
// beam passes within 1 cm of the hole.
TEST(Demo, Fig412DrillingTheDrillStaysOnTheHolesAxisAndTheTorchOnTheHole) {
  simservice::OfflineOptions o;
  o.config = "configs/sim/sim_drill.yaml";
  simservice::OfflineRun run(o);
  const math::Vector3 hole(0.6, -0.2, 1.2), hole_axis = math::Vector3::UnitX();
  Timeline timeline;
  double worst_axis_deg = 0, worst_beam_m = 0, worst_tip_m = 0;
  long guided_steps = 0, failed_pairs = 0;
  int drill = -1, torch = -1;
  const simservice::OfflineSummary s = run.run({}, [&](const sim::World& w, double) {
    if (drill < 0) {
      drill = w.findObject("drill");
      torch = w.findObject("torch");
    }
    failed_pairs += w.diagnostics().failed_collision_pairs;  // narrow phases that gave up (the bit meets the wall)
    const scenario::Engine* e = w.scenarioEngine();
    timeline.see(e, w.time());
    if (e == nullptr || e->state() < 0) return;
    if (e->stateName() != "guided" || e->timeInState() < 0.5) return;
    ++guided_steps;
    const math::SE3& d = w.object(drill).pose();
    const math::SE3& t = w.object(torch).pose();
    // the bit along the drill's −z, the beam along the torch's −z (configs/scenes/drill_wall.yaml)
    const double axis_deg = std::acos(std::clamp(-d.R.col(2).dot(hole_axis), -1.0, 1.0)) * 180.0 / M_PI;
    const math::Vector3 beam = -t.R.col(2), to_hole = hole - t.p;
    const math::Vector3 drill_to_hole = hole - d.p;
    worst_axis_deg = std::max(worst_axis_deg, axis_deg);
    worst_beam_m = std::max(worst_beam_m, (to_hole - to_hole.dot(beam) * beam).norm());
    worst_tip_m = std::max(worst_tip_m, (drill_to_hole - drill_to_hole.dot(hole_axis) * hole_axis).norm());
  });
  std::printf("drilling: %s| guided %ld steps: drill axis within %.3f deg of the hole's, its origin %.4f m off the axis; "
              "torch beam %.4f m from the hole; NaN steps %lld, %.1f s wall\n",
              timeline.str().c_str(), guided_steps, worst_axis_deg, worst_tip_m, worst_beam_m, s.nan_steps, s.wall_s);
  EXPECT_EQ(timeline.states(), (std::vector<std::string>{"grab", "guided", "retract", "done"})) << timeline.str();
  EXPECT_GE(guided_steps, 1900);  // 2.5 s at depth, measured after the 0.5 s blend
  EXPECT_EQ(s.scenario_unapplied_actions, 0);
  EXPECT_LT(worst_axis_deg, 1.0);
  EXPECT_LT(worst_tip_m, 0.01);  // and the drill on the axis: its centre within 1 cm of it
  EXPECT_EQ(failed_pairs, 0);
  EXPECT_LT(worst_beam_m, 0.01);
  EXPECT_EQ(s.nan_steps, 0);
}
