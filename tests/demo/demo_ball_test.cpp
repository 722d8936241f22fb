// Demonstration 2 (thesis 4.3.1, Fig. 4.9–4.10): a ball falls, is caught, put on a table, pushed off it and
// kicked — configs/sim/sim_ball.yaml.
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

namespace {
// configs/scenes/ball.yaml
constexpr double kTableTop = 0.95, kTableFront = 0.70, kTableLeft = -0.35, kRadius = 0.11, kMass = 0.45;
bool startsWith(const std::string& s, const std::string& p) { return s.compare(0, p.size(), p) == 0; }
}  // namespace

// The claims: the falling ball is caught on the hands (it never falls below them while held); put on the table
// it rests there, the table's contact forces carrying its weight (Fig. 3.6); pushed past the edge it falls to
// the floor; the right foot then moves it (a foot–ball contact force) beyond the table's front edge, where it
// lies on the floor.
TEST(Demo, Fig49BallIsCaughtPutOnTheTablePushedOffAndKicked) {
  simservice::OfflineOptions o;
  o.config = "configs/sim/sim_ball.yaml";
  simservice::OfflineRun run(o);
  const char* verbose_env = std::getenv("MANNEQUIN_DEMO_VERBOSE");  // set: print every 0.25 s (or every N s if a number)
  const bool verbose = verbose_env != nullptr;
  const double print_period = verbose && std::atof(verbose_env) > 0 ? std::atof(verbose_env) : 0.25;
  demo_test::Timeline timeline;
  int ball = -1, ball_body = -1, table_body = -1;
  double next_print = 0, lowest_caught = 1e9, table_support = 0, table_support_steps = 0, resting_z = 0;
  double worst_on_table = 0, worst_on_table_at = 0, kick_start_x = 0, foot_force_max = 0, end_x = 0, end_y = 0, end_z = 0;
  std::string worst_on_table_by;
  long foot_push_steps = 0, touched_while_resting = 0;
  bool kick_seen = false;
  const simservice::OfflineSummary s = run.run({}, [&](const sim::World& w, double) {
    if (ball < 0) {
      ball = w.findObject("ball");
      ball_body = w.collisionWorld()->findBody("scene/ball");
      table_body = w.collisionWorld()->findBody("scene/table");
    }
    const scenario::Engine* e = w.scenarioEngine();
    timeline.see(e, w.time());
    const math::Vector3 p = w.object(ball).pose().p;
    // forces on the ball: from the table (upwards), from the right foot
    double from_table = 0, from_foot = 0;
    bool other_on_ball = false;
    for (const sim::ContactReport& c : w.contacts()) {
      if (c.normal_force <= 0 || (c.body_a != ball_body && c.body_b != ball_body)) continue;
      const int other = c.body_a == ball_body ? c.body_b : c.body_a;
      const math::Vector3 on_ball = (c.body_b == ball_body ? 1.0 : -1.0) * c.normal_force * c.normal;
      if (other == table_body) from_table += on_ball.z();
      else other_on_ball = true;
      const std::string name = w.collisionWorld()->bodyName(other);
      if (startsWith(name, "player/foot_r") || startsWith(name, "player/toes_r")) from_foot += on_ball.norm();
    }
    if (verbose && w.time() >= next_print) {
      next_print += print_period;
      std::printf("%6.2f %-9s ball (%.3f %.3f %.3f) table %.2f N foot %.2f N", w.time(), e && e->state() >= 0 ? e->stateName().c_str() : "-", p.x(),
                  p.y(), p.z(), from_table, from_foot);
      for (const sim::ContactReport& c : w.contacts())
        if (c.normal_force > 0 && (c.body_a == ball_body || c.body_b == ball_body))
          std::printf(" [%s %.2f]", w.collisionWorld()->bodyName(c.body_a == ball_body ? c.body_b : c.body_a).c_str(), c.normal_force);
      std::printf("\n");
      for (const sim::ContactReport& c : w.contacts())
        if (c.normal_force > 0 && c.body_a != ball_body && c.body_b != ball_body)
          std::printf("       contact %s - %s %.2f N\n", w.collisionWorld()->bodyName(c.body_a).c_str(), w.collisionWorld()->bodyName(c.body_b).c_str(),
                      c.normal_force);
      for (const sim::DrivenFrame& f : w.controlFrames(0))
        if (f.frame == "hand_r" || f.frame == "hand_l" || f.frame == "foot_r")
          std::printf("       %-7s actual (%.3f %.3f %.3f) target (%.3f %.3f %.3f)\n", f.frame.c_str(), f.actual.p.x(), f.actual.p.y(), f.actual.p.z(),
                      f.target.p.x(), f.target.p.y(), f.target.p.z());
    }
    // the player does not lean on the table: no contact of his with it pushes harder than an arm's weight
    for (const sim::ContactReport& c : w.contacts())
      if ((c.body_a == table_body) != (c.body_b == table_body) && c.body_a != ball_body && c.body_b != ball_body)
        if (c.normal_force > worst_on_table) {
          worst_on_table = c.normal_force;
          worst_on_table_at = w.time();
          worst_on_table_by = w.collisionWorld()->bodyName(c.body_a == table_body ? c.body_b : c.body_a);
        }
    if (e == nullptr || e->state() < 0) return;
    const std::string& st = e->stateName();
    if (st == "caught") lowest_caught = std::min(lowest_caught, p.z());
    // resting on the table: between 3.9 s, when the actor's hand has left it, and 4.2 s, when it comes to push
    // (configs/sim/mocap_ball.yaml); nothing but the table touches it then
    if (st == "on_table" && w.time() >= 3.9 && w.time() < 4.2) {
      table_support += from_table;
      table_support_steps += 1;
      resting_z = p.z();
      if (other_on_ball) ++touched_while_resting;
    }
    if (st == "kick" || st == "rest") {
      if (!kick_seen) kick_start_x = p.x();
      kick_seen = true;
      foot_force_max = std::max(foot_force_max, from_foot);
      if (from_foot > 0) ++foot_push_steps;
    }
    end_x = p.x();
    end_y = p.y();
    end_z = p.z();
  });
  const double mean_support = table_support_steps > 0 ? table_support / table_support_steps : 0;
  std::printf("ball: %s| lowest while held %.3f m; on the table at z %.4f m, the table carries %.3f N (m g = %.3f N); kicked from x = %.3f m to "
              "(%.3f, %.3f, %.3f), foot force up to %.1f N over %ld steps; the player pushes on the table up to %.1f N (%s at %.3f s); NaN steps %lld, %.1f s wall\n",
              timeline.str().c_str(), lowest_caught, resting_z, mean_support, kMass * 9.81, kick_start_x, end_x, end_y, end_z, foot_force_max,
              foot_push_steps, worst_on_table, worst_on_table_by.empty() ? "no contact" : worst_on_table_by.c_str(), worst_on_table_at, s.nan_steps, s.wall_s);
  EXPECT_EQ(timeline.states(), (std::vector<std::string>{"fall", "caught", "on_table", "off_table", "on_floor", "kick", "rest"})) << timeline.str();
  EXPECT_EQ(s.scenario_unapplied_actions, 0);
  EXPECT_GT(lowest_caught, 0.9);                              // held at the hands' height, not dropped
  EXPECT_NEAR(resting_z, kTableTop + kRadius, 0.01);          // on the table top (within the margins)
  EXPECT_GT(table_support_steps, 250);
  EXPECT_EQ(touched_while_resting, 0);
  EXPECT_NEAR(mean_support, kMass * 9.81, 0.01 * kMass * 9.81);  // the table carries its weight (1%)
  EXPECT_GT(foot_push_steps, 0);                              // the foot moved it
  EXPECT_GT(end_x - kick_start_x, 0.15);
  EXPECT_GT(end_x, kTableFront);                              // beyond the table's front edge ...
  EXPECT_GT(end_y, kTableLeft);                               // ... and off its side
  EXPECT_NEAR(end_z, kRadius, 0.01);                          // lying on the floor
  EXPECT_LT(worst_on_table, 40.0);                            // an arm weighs about 4 kg
  EXPECT_EQ(s.nan_steps, 0);
}
