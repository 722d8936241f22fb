// The thesis's demonstrations (4.3.1, Fig. 4.8–4.16) as shipped scenario + scene + capture, run the way
// `mannequin-simulate --scenario` runs them (simservice::OfflineRun), each asserting its figure's claim.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mannequin/scenario/engine.hpp"
#include "mannequin/simservice/offline.hpp"

using namespace mannequin;

namespace {

struct StateSpan {
  std::string state;
  double from = 0, to = 0;
};

}  // namespace

// Demonstration 1, Fig. 4.8: a jump with six control frames (feet, hands, pelvis, head all free, the
// CMU capture 131_03). The scenario names the phases from the floor's push on the feet; the claim: both
// feet leave the floor and land, and the soles never sink below the floor beyond the segments' margin.
TEST(Demo, Fig48JumpWithSixControlFramesBothFeetLeaveTheFloorAndLandWithoutPenetration) {
  simservice::OfflineOptions o;
  o.config = "configs/sim/sim_demo.yaml";
  o.scenario = "configs/scenarios/jump.yaml";
  simservice::OfflineRun run(o);
  std::vector<StateSpan> spans;
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
    if (e->state() >= 0) {
      if (spans.empty() || spans.back().state != e->stateName()) spans.push_back({e->stateName(), w.time(), w.time()});
      spans.back().to = w.time();
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
  std::string timeline;
  for (const StateSpan& sp : spans) timeline += sp.state + " [" + std::to_string(sp.from) + ", " + std::to_string(sp.to) + "] ";
  std::printf("jump: %s| airborne %ld steps (a foot within touching distance in %ld, longest flight %ld steps), lowest sole "
              "%.4f m (margin %.3f), NaN steps %lld, ankles standing at most %.3f m\n",
              timeline.c_str(), airborne_steps, airborne_feet_touching, longest_flight, lowest_sole, margin, s.nan_steps, standing_ankle);
  ASSERT_EQ(spans.size(), 3u) << timeline;
  EXPECT_EQ(spans[0].state, "standing");
  EXPECT_EQ(spans[1].state, "airborne");
  EXPECT_EQ(spans[2].state, "landed");
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
