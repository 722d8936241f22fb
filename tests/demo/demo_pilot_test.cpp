// Demonstration 6 (thesis 4.3.1, Fig. 4.14): a pilot sits down in a cockpit and pushes the throttle lever
// to its end stop, seated, with the seat, backrest, armrest, floor and lever in contact —
// configs/sim/sim_pilot.yaml.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "mannequin/scenario/engine.hpp"
#include "mannequin/simservice/offline.hpp"
#include "timeline.hpp"

using namespace mannequin;

// The claims: the lever reaches its end stop (45° from idle, held there by its limit), with no NaN step; and
// what the figure shows — besides the hand on the lever, many secondary contacts (seat, backrest, armrest,
// floor) carrying the seated pilot. The step time is reported (speed is measured by bench-step, not here).
TEST(Demo, Fig414PilotPushesTheThrottleToItsEndStopWithManySecondaryContacts) {
  simservice::OfflineOptions o;
  o.config = "configs/sim/sim_pilot.yaml";
  simservice::OfflineRun run(o);
  const bool verbose = std::getenv("MANNEQUIN_DEMO_VERBOSE") != nullptr;
  demo_test::Timeline timeline;
  int lever = -1;
  double max_angle = 0, upper = 0, next_print = 0;
  double worst_step_s = 0, constraint_s = 0;
  long steps = 0, at_stop_steps = 0, seated_contact_steps = 0;
  int fewest_seated_contacts = 1 << 30, most_contacts = 0;
  double seat_force_min = 1e9;
  const simservice::OfflineSummary s = run.run({}, [&](const sim::World& w, double) {
    if (lever < 0) {
      lever = w.findObject("throttle");
      upper = w.object(lever).hinge().upper;
    }
    const sim::StepDiagnostics& d = w.diagnostics();
    const double step_s = d.collision_s + d.free_motion_s + d.constraints_s + d.integrate_s;
    ++steps;
    constraint_s += d.constraints_s;
    if (w.time() > 0.1) worst_step_s = std::max(worst_step_s, step_s);
    max_angle = std::max(max_angle, w.object(lever).angle());
    const scenario::Engine* e = w.scenarioEngine();
    if (verbose && w.time() >= next_print) {
      next_print += 0.5;
      for (const auto& f : w.controlFrames(0))
        if (f.frame == "hand_r" || f.frame == "pelvis" || f.frame == "foot_r" || f.frame == "head")
          std::printf("%6.2f %-8s %s actual (%.3f %.3f %.3f) target (%.3f %.3f %.3f)\n", w.time(), e && e->state() >= 0 ? e->stateName().c_str() : "-",
                      f.frame.c_str(), f.actual.p.x(), f.actual.p.y(), f.actual.p.z(), f.target.p.x(), f.target.p.y(), f.target.p.z());
      if (std::getenv("MANNEQUIN_DEMO_CONTACTS"))
        for (const sim::ContactReport& c : w.contacts())
          std::printf("         %s - %s d %.4f f %.1f\n", w.collisionWorld()->bodyName(c.body_a).c_str(),
                      w.collisionWorld()->bodyName(c.body_b).c_str(), c.distance, c.normal_force);
      std::printf("       lever %.2f deg, contacts %d (active %d), step %.0f us\n", w.object(lever).angle() * 180 / M_PI, d.contacts,
                  d.active_contacts, step_s * 1e6);
    }
    timeline.see(e, w.time());
    if (e == nullptr || e->state() < 0) return;
    most_contacts = std::max(most_contacts, d.active_contacts);
    if (e->stateName() == "at_stop") ++at_stop_steps;
    // seated (after sitting down, 4 s): the contacts that carry the pilot, other than the lever
    if (w.time() > 5.0) {
      int seated = 0;
      double up = 0;
      for (const sim::ContactReport& c : w.contacts()) {
        const std::string a = w.collisionWorld()->bodyName(c.body_a), b = w.collisionWorld()->bodyName(c.body_b);
        const bool scene = a == "scene/seat" || b == "scene/seat" || a == "scene/floor" || b == "scene/floor";
        if (scene && c.normal_force > 0) {
          ++seated;
          up += c.normal_force * std::abs(c.normal.z());
        }
      }
      fewest_seated_contacts = std::min(fewest_seated_contacts, seated);
      seat_force_min = std::min(seat_force_min, up);
      ++seated_contact_steps;
    }
  });
  std::printf("pilot: %s| lever max %.3f deg (end stop %.3f deg), %ld steps at the stop; seated: at least %d loaded contacts "
              "with the seat and floor, carrying at least %.1f N upwards; most active contacts %d; step: mean %.1f us "
              "(constraints %.1f us), worst %.0f us; NaN steps %lld, %.1f s wall\n",
              timeline.str().c_str(), max_angle * 180 / M_PI, upper * 180 / M_PI, at_stop_steps, fewest_seated_contacts, seat_force_min,
              most_contacts, s.wall_s / static_cast<double>(std::max(1L, steps)) * 1e6, constraint_s / static_cast<double>(std::max(1L, steps)) * 1e6,
              worst_step_s * 1e6, s.nan_steps, s.wall_s);
  EXPECT_EQ(timeline.states(), (std::vector<std::string>{"seated", "grip", "at_stop", "released"})) << timeline.str();
  EXPECT_EQ(s.scenario_unapplied_actions, 0);
  EXPECT_NEAR(max_angle, upper, 0.5 * M_PI / 180);  // at its end stop, not past it
  EXPECT_GE(at_stop_steps, 900);
  EXPECT_EQ(s.nan_steps, 0);
  EXPECT_GT(seated_contact_steps, 0);
  EXPECT_GE(fewest_seated_contacts, 6);
}
