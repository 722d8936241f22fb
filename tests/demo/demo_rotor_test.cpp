// Demonstration 7 (thesis 4.3.1, Fig. 4.15–4.16): a part placed between two rotor blades with its hole on
// the blades' hole axis, then a pin put through them, each guided by a virtual mechanism acting on the
// object (attach_guide) — configs/sim/sim_rotor.yaml.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "mannequin/math/so3.hpp"
#include "mannequin/scenario/engine.hpp"
#include "mannequin/sim/object_guides.hpp"
#include "mannequin/simservice/offline.hpp"
#include "timeline.hpp"

using namespace mannequin;

namespace {

double angleDeg(const math::Matrix3& a, const math::Matrix3& b) { return math::logSO3(a.transpose() * b).norm() * 180.0 / M_PI; }

}  // namespace

// The claims: the part ends within 1 mm and 1° of its seat (its hole on the axis), and so does the pin;
// while guided, each stays on its guide's line within 1 mm and 1°. The actor's hands are 2–3 cm off
// (configs/sim/mocap_rotor.yaml): the precision is the guides', which the test checks by the distance
// between the right hand's target and where the hand is held.
TEST(Demo, Fig415RotorThePartAndThePinEndInTheirSeatsWithin1mmAnd1Degree) {
  simservice::OfflineOptions o;
  o.config = "configs/sim/sim_rotor.yaml";
  simservice::OfflineRun run(o);
  const bool verbose = std::getenv("MANNEQUIN_DEMO_VERBOSE") != nullptr;
  // the seats (configs/scenarios/rotor.yaml): the part's centre mid-gap with its bar along +y, the pin's
  // centre on the hole's axis, upright
  const math::SE3 part_seat(math::expSO3(math::Vector3(-M_PI / 2, 0, 0)), math::Vector3(0.50, 0.08, 1.03));
  const math::SE3 pin_seat(math::Matrix3::Identity(), math::Vector3(0.50, 0.15, 1.03));
  demo_test::Timeline timeline;
  int part = -1, pin = -1;
  double closest_to_blades = 1.0;  // m, after margins
  double segment_margin = 0;
  double part_off_m = 0, part_off_deg = 0, pin_off_m = 0, pin_off_deg = 0, target_off_m = 0;
  long part_guided = 0, pin_guided = 0, failed_pairs = 0;
  math::SE3 part_end, pin_end;
  double next_print = 0;
  const simservice::OfflineSummary s = run.run({}, [&](const sim::World& w, double) {
    if (part < 0) {
      part = w.findObject("part");
      pin = w.findObject("pin");
    }
    failed_pairs += w.diagnostics().failed_collision_pairs;
    segment_margin = w.config().physics.segment_margin;
    part_end = w.object(part).pose();
    pin_end = w.object(pin).pose();
    const scenario::Engine* e = w.scenarioEngine();
    if (verbose && w.time() >= next_print) {
      next_print += 0.5;
      const auto& fr = w.controlFrames(0);
      for (const auto& f : fr)
        if (f.frame == "hand_r" || f.frame == "hand_l")
          std::printf("%6.2f %-8s %s actual (%.3f %.3f %.3f) target (%.3f %.3f %.3f)\n", w.time(), e && e->state() >= 0 ? e->stateName().c_str() : "-",
                      f.frame.c_str(), f.actual.p.x(), f.actual.p.y(), f.actual.p.z(), f.target.p.x(), f.target.p.y(), f.target.p.z());
      const sim::StepDiagnostics& d = w.diagnostics();
      std::printf("       part (%.3f %.3f %.3f) pin (%.3f %.3f %.3f) contacts %d pen %.4f | collision %.0f us constraints %.0f us "
                  "(lcp %d, pivots %d, solves %d, warm %d)\n",
                  part_end.p.x(), part_end.p.y(), part_end.p.z(), pin_end.p.x(), pin_end.p.y(), pin_end.p.z(), d.contacts,
                  d.max_penetration_m, d.collision_s * 1e6, d.constraints_s * 1e6, d.solver.lcp_size, d.solver.pivots,
                  d.solver.lcp_solves, d.solver.warm);
    }
    if (verbose && w.diagnostics().max_penetration_m > 0.005)
      for (const sim::ContactReport& c : w.contacts())
        if (c.distance < -0.005)
          std::printf("%7.3f penetration: %s - %s distance %.4f at (%.3f %.3f %.3f)\n", w.time(), w.collisionWorld()->bodyName(c.body_a).c_str(),
                      w.collisionWorld()->bodyName(c.body_b).c_str(), c.distance, c.point.x(), c.point.y(), c.point.z());
    timeline.see(e, w.time());
    if (e == nullptr || e->state() < 0) return;
    // not the real geometry's penetration from the start: before the first grasp the objects overlap the hips
    // for a few milliseconds (configs/scenes/rotor_blades.yaml)
    // (and after the release the hand and the handle it gripped part: they overlapped while held). What is
    // asserted: nothing is pushed into the blades — the closest approach of any body to them, after margins.
    if (w.time() > timeline.spans().front().from + 0.05) {
      for (const sim::ContactReport& c : w.contacts())
        if (w.collisionWorld()->bodyName(c.body_a) == "scene/blades" || w.collisionWorld()->bodyName(c.body_b) == "scene/blades")
          closest_to_blades = std::min(closest_to_blades, c.distance);
    }
    const sim::GuideRows* g = w.guides();
    ASSERT_NE(g, nullptr);
    if (g->guided(part) && e->timeInState() > 0.5) {
      ++part_guided;
      part_off_m = std::max(part_off_m, g->positionError(part));
      part_off_deg = std::max(part_off_deg, g->angleError(part) * 180.0 / M_PI);
    }
    if (e->stateName() == "pin" && e->timeInState() > 0.5) {
      ++pin_guided;
      pin_off_m = std::max(pin_off_m, g->positionError(pin));
      pin_off_deg = std::max(pin_off_deg, g->angleError(pin) * 180.0 / M_PI);
    }
    if (e->stateName() == "pin")
      for (const sim::DrivenFrame& f : w.controlFrames(0))
        if (f.frame == "hand_r") target_off_m = std::max(target_off_m, (f.target.p - f.actual.p).norm());
  });
  const double part_m = (part_end.p - part_seat.p).norm(), part_deg = angleDeg(part_end.R, part_seat.R);
  const double pin_m = (pin_end.p - pin_seat.p).norm(), pin_deg = angleDeg(pin_end.R, pin_seat.R);
  std::printf("rotor: %s| part ends %.2e m / %.3f deg from its seat (guided %ld steps: %.2e m / %.3f deg off its line); pin "
              "ends %.2e m / %.3f deg from its seat (guided %ld steps: %.2e m / %.3f deg); the right hand's target up to %.3f m "
              "from the hand while the pin goes in; NaN steps %lld, failed pairs %ld, closest to the blades %.4f m (after margins; max penetration of the run %.4f m), %.1f s wall\n",
              timeline.str().c_str(), part_m, part_deg, part_guided, part_off_m, part_off_deg, pin_m, pin_deg, pin_guided, pin_off_m,
              pin_off_deg, target_off_m, s.nan_steps, failed_pairs, closest_to_blades, s.max_penetration_m, s.wall_s);
  EXPECT_EQ(timeline.states(), (std::vector<std::string>{"carry", "insert", "seated", "pin", "done"})) << timeline.str();
  EXPECT_EQ(s.scenario_unapplied_actions, 0);
  EXPECT_LT(part_m, 0.001);
  EXPECT_LT(part_deg, 1.0);
  EXPECT_LT(pin_m, 0.001);
  EXPECT_LT(pin_deg, 1.0);
  EXPECT_GT(part_guided, 1000);
  EXPECT_GT(pin_guided, 500);
  EXPECT_LT(part_off_m, 0.001);
  EXPECT_LT(part_off_deg, 1.0);
  EXPECT_LT(pin_off_m, 0.001);
  EXPECT_LT(pin_off_deg, 1.0);
  // the actor is not that precise: its target for the right hand is more than 1.5 cm from where the guide holds it
  EXPECT_GT(target_off_m, 0.015);
  EXPECT_EQ(failed_pairs, 0);
  // nothing pushed through the blades: the shells overlap by less than the segments' margin (5 mm), so the real
  // geometry does not touch
  EXPECT_GT(closest_to_blades, -segment_margin);
  EXPECT_EQ(s.nan_steps, 0);
}
