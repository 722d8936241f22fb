// sim::World with physics, objects and several mannequins (thesis 3.2, 3.3.2.1, 4.3.1, Fig. 4.17):
// the balance distance of a standing mannequin, the table scene's objects resting in the World, a hand
// driven 10 cm into a table stopping on it, two actors (two mocap sources) lifting a box by its handles
// and carrying it 1 m.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>

#include "actor.hpp"
#include "mannequin/collision/scene.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/sim/controller_stepper.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/scenario/engine.hpp"
#include "mannequin/scenario/scenario.hpp"
#include "../constraints/male50_fixture.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

using namespace mannequin;
using namespace mannequin::sim;

namespace {
using mannequin::testing_fixture::male50;

using mannequin::testing::kActorBodies;

MannequinSetup actorSetup(const std::string& name, const std::string& source) {
  MannequinSetup m;
  m.name = name;
  m.model = male50();
  m.mocap_source = source;
  for (const char* b : kActorBodies) m.frames.push_back({b, b});
  m.controller = control::loadControllerConfig("configs/control/mocap.yaml");
  return m;
}

/// The frames of the standing mannequin placed by `base` (world), as a mocap frame; `moved` replaces
/// some bodies' positions (world), keeping their standing orientation.
mocap::Frame actorFrame(std::int64_t stamp_ns, const math::SE3& base, const std::map<std::string, math::Vector3>& moved = {}) {
  static const skeleton::Data standing = [] {
    skeleton::Data d(male50());
    skeleton::forwardKinematics(male50(), d, skeleton::standingConfiguration(male50()));
    return d;
  }();
  mocap::Frame f;
  f.stamp_ns = stamp_ns;
  f.sequence = static_cast<std::uint64_t>(stamp_ns / 1000000 + 1);
  for (const char* b : kActorBodies) {
    math::SE3 T = base * standing.oMf[static_cast<std::size_t>(male50().frameIndex(b))];
    if (auto it = moved.find(b); it != moved.end()) T.p = it->second;
    f.bodies.push_back({b, T, true});
  }
  return f;
}

/// Standing frame `body` placed by `base` (world).
math::SE3 standingFrame(const math::SE3& base, const std::string& body) {
  skeleton::Data d(male50());
  skeleton::forwardKinematics(male50(), d, skeleton::standingConfiguration(male50()));
  return base * d.oMf[static_cast<std::size_t>(male50().frameIndex(body))];
}

math::SE3 placed(double x, double y, double yaw) {
  return math::SE3(math::expSO3(math::Vector3(0, 0, yaw)), math::Vector3(x, y, 0));
}

double smooth(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * (3 - 2 * s);
}

SimConfig physicsConfigOfScene(const std::string& scene_yaml) {
  SimConfig c;
  c.physics.enabled = true;
  c.physics.scene = collision::parseScene(scene_yaml, "test-scene.yaml");
  return c;
}

/// Steps the World at 1 kHz for `seconds`, feeding each source a frame every 10 ms from `frames(t)`.
/// `each` runs after every step; a false return stops early (returns false).
bool run(World& w, double t0, double seconds, const std::function<void(double)>& feed,
         const std::function<bool(double)>& each = nullptr) {
  const long steps = std::lround(seconds / w.config().step);
  for (long k = 0; k < steps; ++k) {
    const double t = t0 + static_cast<double>(k) * w.config().step;
    if (k % 10 == 0) feed(t);
    if (!w.step()) return false;
    if (each && !each(t)) return false;
  }
  return true;
}

std::int64_t ns(double t) { return static_cast<std::int64_t>(std::llround(t * 1e9)); }

double normalForceOn(const World& w, int body) {
  double f = 0;
  for (const ContactReport& c : w.contacts())
    if (c.body_a == body || c.body_b == body) f += c.normal_force;
  return f;
}
}  // namespace

// Coplanar balance (3.22): the standing mannequin's CoM projects inside the support polygon of its
// feet's floor contacts; its signed distance is published, positive, and smaller than the half-width
// of the stance (the feet are ~0.2 m apart, so the CoM is at most ~0.15 m inside any edge).
TEST(WorldPhysics, StandingBalanceDistanceIsPositiveInsideTheFeet) {
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  World w(std::move(setups), physicsConfigOfScene("bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n"));
  const math::SE3 base = placed(0, 0, 0);
  w.addMocap(actorFrame(0, base));
  w.anchor(0);
  ASSERT_TRUE(w.calibrated(0));
  ASSERT_TRUE(run(w, 0, 1.0, [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base)); }));
  const MannequinDiagnostics& md = w.mannequinDiagnostics(0);
  std::printf("standing: %d support points, balance distance %.4f m, CoM (%.3f, %.3f, %.3f)\n", md.support_points,
              md.balance_distance_m, md.com.x(), md.com.y(), md.com.z());
  EXPECT_GE(md.support_points, 3);
  ASSERT_TRUE(std::isfinite(md.balance_distance_m));
  EXPECT_GT(md.balance_distance_m, 0.02);
  EXPECT_LT(md.balance_distance_m, 0.2);
  EXPECT_GT(md.com.z(), 0.8);  // a standing adult's CoM: ~55% of 1.75 m
  EXPECT_LT(md.com.z(), 1.1);
}

// The stability margin in disturbing forces (PhysicsConfig::force_margin_period, libs/balance): standing,
// the largest horizontal push at the CoM the feet hold is positive and below what statics allows — μ m g
// (sliding) and m g ℓ / h_com with ℓ the farthest support point's horizontal distance from the CoM
// (tipping about the support's edge); lifted off the floor by its actor, nothing holds it: 0.
TEST(WorldPhysics, TheForceMarginOfAStandingMannequinIsBelowStaticsBoundsAndZeroInTheAir) {
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  SimConfig cfg = physicsConfigOfScene("friction: {default: 0.8}\nbodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n");
  cfg.physics.force_margin_period = 0.05;
  World w(std::move(setups), cfg);
  EXPECT_TRUE(std::isnan(w.mannequinDiagnostics(0).force_margin_n)) << "not evaluated before calibration";
  const math::SE3 base = placed(0, 0, 0);
  w.addMocap(actorFrame(0, base));
  w.anchor(0);
  ASSERT_TRUE(w.calibrated(0));
  ASSERT_TRUE(run(w, 0, 1.0, [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base)); }));
  const MannequinDiagnostics& md = w.mannequinDiagnostics(0);
  const double mg = male50().totalMass() * 9.81, mu = cfg.physics.scene.default_mu;
  // a push along d tips the mannequin about the support's farthest edge in that direction: it holds at most
  // m g ℓ_d / h with ℓ_d = max over the support points of (p − CoM)·d; the margin is the smallest over ±x, ±y
  double tipping = std::numeric_limits<double>::infinity();
  for (const math::Vector3& d : {math::Vector3(1, 0, 0), math::Vector3(-1, 0, 0), math::Vector3(0, 1, 0), math::Vector3(0, -1, 0)}) {
    double extent = -std::numeric_limits<double>::infinity();
    for (const ContactReport& c : w.contacts()) extent = std::max(extent, (c.point - md.com).dot(d));
    tipping = std::min(tipping, mg * std::max(extent, 0.0) / md.com.z());
  }
  std::printf("standing: force margin %.1f N from %d contact points (sliding bound %.0f N, tipping bound %.1f N)\n",
              md.force_margin_n, md.force_margin_contacts, mu * mg, tipping);
  ASSERT_TRUE(std::isfinite(md.force_margin_n));
  EXPECT_GE(md.force_margin_contacts, 3);
  EXPECT_GT(md.force_margin_n, 5.0);
  EXPECT_LE(md.force_margin_n, mu * mg + 1.0);
  EXPECT_LE(md.force_margin_n, tipping + 1.0);
  // the actor jumps: every body 0.4 m up, the mannequin follows and its feet leave the floor
  const math::SE3 up = placed(0, 0, 0) * math::SE3(math::Matrix3::Identity(), math::Vector3(0, 0, 0.4));
  ASSERT_TRUE(run(w, 1.0, 0.6, [&](double t) { w.addMocap(actorFrame(ns(t) + 1, up)); }));
  std::printf("lifted: sole height %.3f m, force margin %.1f N from %d contact points\n", md.sole_height_m, md.force_margin_n,
              md.force_margin_contacts);
  ASSERT_GT(md.sole_height_m, w.config().physics.foot_contact_tolerance + 0.005) << "the feet left the floor";
  EXPECT_EQ(md.force_margin_n, 0.0);
  EXPECT_EQ(md.force_margin_contacts, 0);
}

// The shipped table scene in a World with a standing mannequin: its ball (0.45 kg) and tray (0.6 kg)
// are systems of the step's LCP and rest on the table, the contact forces under each equal to its
// weight within 1% (Fig. 3.6), and they appear among the World's objects.
TEST(WorldPhysics, TableSceneObjectsRestInTheWorld) {
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  SimConfig cfg;
  cfg.physics.enabled = true;
  cfg.physics.scene = collision::loadScene("configs/scenes/table.yaml");
  World w(std::move(setups), cfg);
  ASSERT_EQ(w.numObjects(), 2);  // the tool has no mass: kinematic, not an object
  const int ball = w.findObject("ball"), tray = w.findObject("tray");
  ASSERT_GE(ball, 0);
  ASSERT_GE(tray, 0);
  EXPECT_EQ(w.findObject("tool"), -1);
  const math::SE3 base = placed(-0.2, 0, 0);
  w.addMocap(actorFrame(0, base));
  w.anchor(0);
  double ball_lowest = 1e9;
  ASSERT_TRUE(run(w, 0, 1.5, [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base)); },
                  [&](double) {
                    ball_lowest = std::min(ball_lowest, w.object(ball).pose().p.z());
                    return true;
                  }));
  const double g = 9.81;
  const double f_ball = normalForceOn(w, w.objectBody(ball)), f_tray = normalForceOn(w, w.objectBody(tray));
  std::printf("table scene: ball rests at z = %.5f m (lowest %.5f) on %.4f N (m g = %.4f N), tray on %.4f N (%.4f N)\n",
              w.object(ball).pose().p.z(), ball_lowest, f_ball, 0.45 * g, f_tray, 0.6 * g);
  EXPECT_NEAR(f_ball, 0.45 * g, 0.01 * 0.45 * g);
  EXPECT_NEAR(f_tray, 0.6 * g, 0.01 * 0.6 * g);
  // the ball (radius 0.11) on the top at 0.75 m: its centre never below 0.75 + 0.11 − margins
  EXPECT_GT(ball_lowest, 0.86 - 0.005);
  // the collision world moves the objects' bodies with them
  EXPECT_LT((w.collisionWorld()->bodyPose(w.objectBody(ball)).p - w.object(ball).pose().p).norm(), 1e-12);
}

// Fig. 4.17: a hand target driven 10 cm below a table's top; the hand stops on the top (the contact
// carries the coupling's push) and the real geometry penetrates less than the margin.
TEST(WorldPhysics, AHandDrivenIntoATableStopsOnIt) {
  const double top = 0.85;
  char scene[512];
  std::snprintf(scene, sizeof scene,
                "bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n"
                "  - name: table\n    pose: {position: [0.45, -0.25, %.3f]}\n    shape: {type: box, size: [0.3, 0.3, 0.04]}\n",
                top - 0.02);
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  World w(std::move(setups), physicsConfigOfScene(scene));
  const math::SE3 base = placed(0, 0, 0);
  const math::Vector3 hang = standingFrame(base, "hand_r").p;
  // the hand hangs fingers down (standing orientation): up in front of the body first, then over the
  // table, so that the fingers pass above its front edge
  const math::Vector3 up(0.15, -0.22, top + 0.35), above(0.40, -0.22, top + 0.25), into(0.40, -0.22, top - 0.10);
  const auto target = [&](double t) {  // hanging → up (1.5 s) → above the table (1 s) → 10 cm below its top (1 s)
    if (t < 1.5) return hang + smooth(t / 1.5) * (up - hang);
    if (t < 2.5) return up + smooth((t - 1.5) / 1.0) * (above - up);
    return above + smooth((t - 2.5) / 1.0) * (into - above);
  };
  w.addMocap(actorFrame(0, base));
  w.anchor(0);
  const int table = w.collisionWorld()->findBody("scene/table");
  const int hand = w.collisionWorld()->segmentBody(0, w.model(0).findSegment("hand_r"));
  ASSERT_GE(table, 0);
  ASSERT_GE(hand, 0);
  const double margin = w.config().physics.segment_margin;
  double worst_penetration = 0;
  ASSERT_TRUE(run(w, 0, 5.0, [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base, {{"hand_r", target(t)}})); },
                  [&](double) {
                    worst_penetration = std::max(worst_penetration, w.diagnostics().max_penetration_m);
                    return true;
                  }));
  const double pushed = normalForceOn(w, table);
  double hand_on_table = 0;  // the hand segment's contacts with the table
  for (const ContactReport& c : w.contacts())
    if ((c.body_a == hand && c.body_b == table) || (c.body_a == table && c.body_b == hand)) hand_on_table += c.normal_force;
  const DrivenFrame& hf = w.controlFrames(0)[3];
  ASSERT_EQ(hf.frame, "hand_r");
  std::printf("hand 10 cm into a table: target z %.3f, hand frame z %.4f (top %.3f), hand on table %.2f N (table "
              "total %.2f N), worst penetration %.5f m (margin %.3f)\n",
              hf.target.p.z(), hf.actual.p.z(), top, hand_on_table, pushed, worst_penetration, margin);
  EXPECT_GT(hand_on_table, 1.0);                // the hand presses on the table
  EXPECT_GT(hf.actual.p.z(), top);              // stopped on the top (the frame is at the wrist, above the fingers)
  EXPECT_GT(hf.position_error, 0.05);           // far from its target: the table holds it
  EXPECT_LT(worst_penetration, margin);         // the real geometry: less than the margin
  EXPECT_EQ(w.failedSteps(), 0u);
}

// Two actors, two mocap sources: they face each other across a 4 kg box with two handles, put their
// hands on the handles, grasp (bilateral rows), lift it 10 cm and carry it 1 m sideways. No hand slips
// on its handle (relative pose held within 2 mm and 0.02 rad), the box never drops, each mannequin
// carries part of its weight, and it arrives 1 m away.
TEST(WorldPhysics, TwoMannequinsLiftABoxByItsHandlesAndCarryIt1m) {
  const char* scene =
      "friction: {default: 0.05}\n"  // the feet slide on the floor as the actors shuffle sideways
      "bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n"
      "  - name: stand\n    pose: {position: [0, 0, 0.4]}\n    shape: {type: box, size: [0.3, 0.3, 0.8]}\n"
      "  - name: box\n    movable: true\n    pose: {position: [0, 0, 0.951]}\n    mass: 4\n"
      "    margin: 0.002\n"  // the box rests 2 mm above its stand: box–box penetration (FCL's EPA) never runs
      "    inertia: [0.05, 0.07, 0.08]\n"
      "    shapes:\n"
      "      - {type: box, size: [0.5, 0.36, 0.3]}\n"
      "      - {type: box, size: [0.06, 0.24, 0.03], pose: {position: [-0.28, 0, 0.1]}}\n"
      "      - {type: box, size: [0.06, 0.24, 0.03], pose: {position: [0.28, 0, 0.1]}}\n";
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("alice", "rig_a"));
  setups.push_back(actorSetup("bob", "rig_b"));
  World w(std::move(setups), physicsConfigOfScene(scene));
  ASSERT_EQ(w.mocapSources().size(), 3u);  // "" and the two rigs
  const int box = w.findObject("box");
  ASSERT_GE(box, 0);
  const math::SE3 base_a = placed(-0.62, 0, 0), base_b = placed(0.62, 0, M_PI);
  // handle grip points: the left/right ends of each handle bar, on its top
  const double hz = 0.951 + 0.1 + 0.015 + 0.03;
  const auto handTargets = [&](bool a, double lift, double shift) {
    const double x = a ? -0.28 : 0.28;
    // alice faces +x: her left hand is at +y; bob faces −x: his left hand is at −y
    const double yl = a ? 0.09 : -0.09;
    return std::map<std::string, math::Vector3>{{"hand_l", math::Vector3(x, yl + shift, hz + lift)},
                                                {"hand_r", math::Vector3(x, -yl + shift, hz + lift)}};
  };
  // phases: reach (1.5 s, settle 0.3 s), grasp, lift 10 cm (0.7 s), hold (0.5 s), carry 1 m along +y (2 s), hold (0.3 s)
  double lift = 0, shift = 0, reach = 0;
  const auto feed = [&](double t) {
    for (const bool a : {true, false}) {
      const math::SE3 base = (a ? base_a : base_b);
      math::SE3 moved_base = base;
      moved_base.p.y() += shift;
      std::map<std::string, math::Vector3> m = handTargets(a, lift, shift);
      if (reach < 1) {
        const math::Vector3 hl = standingFrame(base, "hand_l").p, hr = standingFrame(base, "hand_r").p;
        m["hand_l"] = hl + reach * (m["hand_l"] - hl);
        m["hand_r"] = hr + reach * (m["hand_r"] - hr);
      }
      w.addMocap(actorFrame(ns(t) + 1, moved_base, m), a ? "rig_a" : "rig_b");
    }
  };
  w.addMocap(actorFrame(0, base_a), "rig_a");
  w.addMocap(actorFrame(0, base_b), "rig_b");
  w.anchor(0, "rig_a");
  w.anchor(0, "rig_b");
  ASSERT_TRUE(w.calibrated(0));
  ASSERT_TRUE(w.calibrated(1));
  double t = 0;
  ASSERT_TRUE(run(w, t, 1.8, [&](double tt) {
    reach = smooth(tt / 1.5);
    feed(tt);
  }));
  t += 1.8;
  // grasp where the hands are (the handles between them are what they hold)
  std::vector<int> handles;
  for (int m = 0; m < 2; ++m)
    for (const char* h : {"hand_l", "hand_r"}) {
      const int g = w.grasp(m, h, "box");
      ASSERT_GE(g, 0) << w.name(m) << " " << h;
      handles.push_back(g);
    }
  const auto relative = [&](int m, const char* h) {
    const math::SE3& oMh = w.data(m).oMf[static_cast<std::size_t>(w.model(m).frameIndex(h))];
    return oMh.inverse() * w.object(box).pose();
  };
  std::vector<math::SE3> grip0;
  for (int m = 0; m < 2; ++m)
    for (const char* h : {"hand_l", "hand_r"}) grip0.push_back(relative(m, h));
  const double z0 = w.object(box).pose().p.z(), y0 = w.object(box).pose().p.y();
  double worst_slip = 0, worst_turn = 0, lowest = 1e9;
  const auto check = [&](double) {
    int i = 0;
    for (int m = 0; m < 2; ++m)
      for (const char* h : {"hand_l", "hand_r"}) {
        const math::SE3 d = grip0[static_cast<std::size_t>(i++)].inverse() * relative(m, h);
        worst_slip = std::max(worst_slip, d.p.norm());
        worst_turn = std::max(worst_turn, math::logSO3(d.R).norm());
      }
    lowest = std::min(lowest, w.object(box).pose().p.z() - z0);
    return true;
  };
  ASSERT_TRUE(run(w, t, 1.2, [&](double tt) {
    lift = 0.10 * smooth((tt - 1.8) / 0.7);
    feed(tt);
  }, check));
  t += 1.2;
  const double lifted = w.object(box).pose().p.z() - z0;
  // held still: the weight is carried by the four grasps, their vertical forces sum to m g
  double up = 0;
  for (const int g : handles) up += w.graspForce(g).z();
  // what the ergonomic report reads: the grasps held (each mannequin's two hands on the box) and the force
  // on each hand, its grasp's pull: together the box's weight, downward
  const std::vector<GraspState> held = w.grasps();
  ASSERT_EQ(held.size(), 4u);
  math::Vector3 on_hands = math::Vector3::Zero();
  for (int m = 0; m < 2; ++m) {
    int mine = 0;
    for (const GraspState& g : held)
      if (g.mannequin == m) {
        ++mine;
        EXPECT_EQ(g.object, box);
        EXPECT_NEAR((g.force - w.graspForce(g.handle)).norm(), 0.0, 1e-12);
      }
    EXPECT_EQ(mine, 2);
    const auto f = w.handForces(m);
    on_hands += f[0] + f[1];
  }
  std::printf("forces on the four hands: (%.3f, %.3f, %.3f) N\n", on_hands.x(), on_hands.y(), on_hands.z());
  EXPECT_NEAR(on_hands.z(), -4 * 9.81, 0.02 * 4 * 9.81);
  ASSERT_TRUE(run(w, t, 2.3, [&](double tt) {
    shift = 1.0 * smooth((tt - 3.0) / 2.0);
    feed(tt);
  }, check));
  const double moved = w.object(box).pose().p.y() - y0;
  std::printf("two mannequins carry a 4 kg box: lifted %.4f m, grasps carry %.3f N (m g = %.3f N), moved %.4f m, "
              "worst hand slip %.2e m / %.2e rad, lowest %.4f m below the start, %d contacts\n",
              lifted, up, 4 * 9.81, moved, worst_slip, worst_turn, -lowest, w.diagnostics().contacts);
  EXPECT_GT(lifted, 0.07);                        // lifted off its stand (10 cm target)
  EXPECT_NEAR(up, 4 * 9.81, 0.02 * 4 * 9.81);     // the hands carry its weight (a first-order body at rest)
  EXPECT_NEAR(moved, 1.0, 0.05);                  // carried 1 m
  EXPECT_LT(worst_slip, 2e-3);                    // no hand slips on its handle
  EXPECT_LT(worst_turn, 0.02);
  EXPECT_GT(lowest, -0.01);                       // the box never drops
  EXPECT_EQ(w.failedSteps(), 0u);
  for (const int g : handles) EXPECT_TRUE(w.release(g));
  EXPECT_FALSE(w.release(handles[0]));
}

TEST(WorldPhysics, GraspErrorsNameWhatIsWrong) {
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  SimConfig cfg;
  cfg.physics.enabled = true;
  cfg.physics.scene = collision::loadScene("configs/scenes/table.yaml");
  World w(std::move(setups), cfg);
  const auto message = [&](int m, const std::string& f, const std::string& o) {
    try {
      w.grasp(m, f, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(0, "hand_x", "ball").find("hand_x"), std::string::npos);
  EXPECT_NE(message(0, "hand_l", "anvil").find("anvil"), std::string::npos);
  EXPECT_NE(message(3, "hand_l", "ball").find("3"), std::string::npos);
  EXPECT_FALSE(w.addMocap(actorFrame(0, placed(0, 0, 0)), "no_such_rig"));
  EXPECT_EQ(w.latestMocap("no_such_rig"), nullptr);
}

// 60 s standing with both hands pressed on a table (their targets 2 cm below its top): the contacts
// hold the hands and the energy stays bounded — after the hands have settled (10 s), the constraint
// forces do no net work (a port that injected energy would show chattering or drift), the mannequin
// stops moving, and the hands stay on the table without penetrating beyond the margin.
TEST(WorldPhysics, SixtySecondsWithBothHandsOnATableKeepTheEnergyBounded) {
  const double top = 0.85;
  const std::string scene =
      "bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n"
      "  - name: table\n    pose: {position: [0.45, 0, 0.83]}\n    shape: {type: box, size: [0.3, 0.8, 0.04]}\n";
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  World w(std::move(setups), physicsConfigOfScene(scene));
  const math::SE3 base = placed(0, 0, 0);
  std::map<std::string, math::Vector3> hang, up, on;
  for (const char* h : {"hand_l", "hand_r"}) {
    hang[h] = standingFrame(base, h).p;
    const double y = hang[h].y();
    up[h] = math::Vector3(0.15, y, top + 0.35);
    on[h] = math::Vector3(0.40, y, top - 0.02);
  }
  const auto targets = [&](double t) {
    std::map<std::string, math::Vector3> m;
    for (const char* h : {"hand_l", "hand_r"}) {
      const std::string k = h;
      m[k] = t < 1.5 ? hang[k] + smooth(t / 1.5) * (up[k] - hang[k]) : up[k] + smooth((t - 1.5) / 1.5) * (on[k] - up[k]);
    }
    return m;
  };
  w.addMocap(actorFrame(0, base));
  w.anchor(0);
  const auto* cs = dynamic_cast<const ControllerStepper*>(&w.stepper(0));
  ASSERT_NE(cs, nullptr);
  const control::Controller& ctl = cs->controller();
  const int table = w.collisionWorld()->findBody("scene/table");
  const int hand_l = w.collisionWorld()->segmentBody(0, w.model(0).findSegment("hand_l"));
  const int hand_r = w.collisionWorld()->segmentBody(0, w.model(0).findSegment("hand_r"));
  const auto feed = [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base, targets(t)), ""); };
  ASSERT_TRUE(run(w, 0, 10.0, feed));
  const double e_constraint0 = ctl.constraintPort().energy, e_internal0 = ctl.internalPort().energy;
  double max_speed = 0, worst_penetration = 0;
  long steps_both_on = 0, steps = 0;
  ASSERT_TRUE(run(w, 10.0, 50.0, feed, [&](double) {
    max_speed = std::max(max_speed, w.qdot(0).tail(w.model(0).nv - 6).cwiseAbs().maxCoeff());
    worst_penetration = std::max(worst_penetration, w.diagnostics().max_penetration_m);
    bool l = false, r = false;
    for (const ContactReport& c : w.contacts()) {
      if (c.normal_force <= 0 || (c.body_a != table && c.body_b != table)) continue;
      l = l || c.body_a == hand_l || c.body_b == hand_l;
      r = r || c.body_a == hand_r || c.body_b == hand_r;
    }
    steps_both_on += (l && r) ? 1 : 0;
    ++steps;
    return true;
  }));
  const double de_constraint = ctl.constraintPort().energy - e_constraint0;
  const double de_internal = ctl.internalPort().energy - e_internal0;
  std::printf("60 s, both hands on a table: constraint port %.3e J and internal port %.3e J over the last 50 s, max "
              "joint speed %.2e rad/s, both hands pressing in %ld/%ld steps, worst penetration %.5f m\n",
              de_constraint, de_internal, max_speed, steps_both_on, steps, worst_penetration);
  EXPECT_LT(std::abs(de_constraint), 0.05);  // J: no energy injected by the contacts at rest
  EXPECT_LT(std::abs(de_internal), 0.05);
  EXPECT_LT(max_speed, 0.01);                // rad/s: at rest, no oscillation building up
  EXPECT_EQ(steps_both_on, steps);
  EXPECT_LT(worst_penetration, w.config().physics.segment_margin);
  EXPECT_EQ(w.failedSteps(), 0u);
}

namespace {
/// Sum of the normal forces between bodies named "<a>/..." and "<b>/..." (mannequin names, or one
/// mannequin and "scene").
double forceBetween(const World& w, const std::string& a, const std::string& b, const std::string& seg_a = "",
                    const std::string& seg_b = "") {
  const collision::CollisionWorld& cw = *w.collisionWorld();
  const auto is = [&](int body, const std::string& owner, const std::string& seg) {
    const std::string& n = cw.bodyName(body);
    return n.rfind(owner + "/", 0) == 0 && (seg.empty() || n == owner + "/" + seg);
  };
  double f = 0;
  for (const ContactReport& c : w.contacts())
    if ((is(c.body_a, a, seg_a) && is(c.body_b, b, seg_b)) || (is(c.body_a, b, seg_b) && is(c.body_b, a, seg_a)))
      f += c.normal_force;
  return f;
}
}  // namespace

// Inter-mannequin contacts: two actors face each other and reach for the same point with a hand; the
// hands meet and stop each other (contact rows between the two mannequins' segments, forces on both),
// the real geometry penetrating less than the margin.
TEST(WorldPhysics, TwoMannequinsReachingForTheSamePointStopEachOther) {
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("alice", "rig_a"));
  setups.push_back(actorSetup("bob", "rig_b"));
  World w(std::move(setups), physicsConfigOfScene("bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n"));
  const math::SE3 base_a = placed(-0.5, 0, 0), base_b = placed(0.5, 0, M_PI);
  // alice's right hand and bob's left hand (both at −y) each aim 10 cm past the middle
  const math::Vector3 goal_a(0.10, -0.2, 1.15), goal_b(-0.10, -0.2, 1.15);
  const math::Vector3 from_a = standingFrame(base_a, "hand_r").p, from_b = standingFrame(base_b, "hand_l").p;
  const auto feed = [&](double t) {
    const double s = smooth(t / 1.5);
    w.addMocap(actorFrame(ns(t) + 1, base_a, {{"hand_r", from_a + s * (goal_a - from_a)}}), "rig_a");
    w.addMocap(actorFrame(ns(t) + 1, base_b, {{"hand_l", from_b + s * (goal_b - from_b)}}), "rig_b");
  };
  feed(0);
  w.anchor(0, "rig_a");
  w.anchor(0, "rig_b");
  double worst_penetration = 0;
  ASSERT_TRUE(run(w, 0, 2.5, feed, [&](double) {
    worst_penetration = std::max(worst_penetration, w.diagnostics().max_penetration_m);
    return true;
  }));
  const double between = forceBetween(w, "alice", "bob");
  const double err_a = w.controlFrames(0)[3].position_error, err_b = w.controlFrames(1)[2].position_error;
  std::printf("two actors reach for one point: %.2f N between them, hand errors %.3f / %.3f m, worst penetration %.5f m\n",
              between, err_a, err_b, worst_penetration);
  EXPECT_GT(between, 1.0);           // they push on each other
  EXPECT_GT(err_a, 0.02);            // neither reaches its goal 10 cm past the other's hand:
  EXPECT_GT(err_b, 0.02);
  EXPECT_GT(err_a + err_b, 0.05);    // between them, most of the 20 cm the goals cross by
  EXPECT_LT(worst_penetration, w.config().physics.segment_margin);
  EXPECT_EQ(w.failedSteps(), 0u);
}

// A mannequin not yet calibrated has no place of its own: it stands where it was built (at the origin,
// like every other mannequin built there) and touches nothing but the static scene. Alice's actor
// shows up first, at the origin, where Bob (whose actor has not come yet) also stands: Alice is
// calibrated there and tracks her actor, no contact pushes the two apart, and Bob stays on the floor.
// (Were Bob's segments contacts of Alice's, the overlap of two whole bodies would throw Alice off her
// targets: the sim service's two-source test did so, whenever one source's frames came first.)
TEST(WorldPhysics, AMannequinNotYetCalibratedTouchesOnlyTheStaticScene) {
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("alice", "rig_a"));
  setups.push_back(actorSetup("bob", "rig_b"));
  World w(std::move(setups), physicsConfigOfScene("bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n"));
  const math::SE3 base = placed(0, 0, 0);
  const auto feed = [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base), "rig_a"); };
  feed(0);
  w.anchor(0, "rig_a");
  ASSERT_TRUE(w.calibrated(0));
  ASSERT_FALSE(w.calibrated(1));
  double between = 0;
  bool bob_on_floor = true;
  ASSERT_TRUE(run(w, 0, 1.0, feed, [&](double) {
    between = std::max(between, forceBetween(w, "alice", "bob"));
    bob_on_floor = bob_on_floor && w.mannequinDiagnostics(1).foot_contact;
    return true;
  }));
  EXPECT_EQ(between, 0.0) << "contact forces between a calibrated mannequin and one not yet calibrated";
  bool any_pair = false;
  const collision::CollisionWorld& cw = *w.collisionWorld();
  for (const ContactReport& c : w.contacts()) {
    const std::string& a = cw.bodyName(c.body_a);
    const std::string& b = cw.bodyName(c.body_b);
    any_pair = any_pair || (a.rfind("alice/", 0) == 0 && b.rfind("bob/", 0) == 0) ||
               (a.rfind("bob/", 0) == 0 && b.rfind("alice/", 0) == 0);
  }
  EXPECT_FALSE(any_pair) << "contact rows between alice and bob";
  for (const DrivenFrame& f : w.controlFrames(0))
    EXPECT_LT(f.position_error, 0.02) << "alice " << f.frame;
  EXPECT_TRUE(bob_on_floor) << "the uncalibrated mannequin keeps its floor contacts";
  EXPECT_EQ(w.failedSteps(), 0u);
}

// Self contacts (physics.self_collision): the two hands of one mannequin driven towards each other in
// front of the chest, each 4 cm past the midline. Without self contacts they pass through each other and
// reach their targets; with them the arms push on each other (forces between the mannequin's own
// segments: hands, forearms), stop short of their targets and the real geometry never penetrates beyond the margin.
TEST(WorldPhysics, SelfContactsStopTwoHandsDrivenThroughEachOther) {
  struct Run {
    double max_self_force = 0, worst_penetration = 0, final_error = 0;
  };
  const auto drive = [](bool self_collision) {
    std::vector<MannequinSetup> setups;
    setups.push_back(actorSetup("operator", ""));
    SimConfig cfg = physicsConfigOfScene("bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n");
    cfg.physics.self_collision = self_collision;
    World w(std::move(setups), cfg);
    const math::SE3 base = placed(0, 0, 0);
    const math::Vector3 hang_l = standingFrame(base, "hand_l").p, hang_r = standingFrame(base, "hand_r").p;
    const math::Vector3 front_l(0.35, 0.15, 1.1), front_r(0.35, -0.15, 1.1);  // apart in front of the chest
    const math::Vector3 goal_l(0.35, -0.04, 1.1), goal_r(0.35, 0.04, 1.1);    // then across the midline
    const auto target = [&](double t, const math::Vector3& hang, const math::Vector3& front, const math::Vector3& goal) {
      if (t < 1.5) return math::Vector3(hang + smooth(t / 1.5) * (front - hang));
      return math::Vector3(front + smooth((t - 1.5) / 1.0) * (goal - front));
    };
    w.addMocap(actorFrame(0, base));
    w.anchor(0);
    Run r;
    EXPECT_TRUE(run(w, 0, 3.5,
                    [&](double t) {
                      w.addMocap(actorFrame(ns(t) + 1, base,
                                            {{"hand_l", target(t, hang_l, front_l, goal_l)},
                                             {"hand_r", target(t, hang_r, front_r, goal_r)}}));
                    },
                    [&](double) {
                      r.worst_penetration = std::max(r.worst_penetration, w.diagnostics().max_penetration_m);
                      r.max_self_force = std::max(r.max_self_force, forceBetween(w, "operator", "operator"));
                      return true;
                    }));
    r.final_error = w.controlFrames(0)[2].position_error + w.controlFrames(0)[3].position_error;
    EXPECT_EQ(w.failedSteps(), 0u);
    return r;
  };
  const Run off = drive(false), on = drive(true);
  std::printf("hands through each other: without self contacts errors %.3f m (sum of both); with them %.3f m, largest "
              "self-contact force %.2f N, worst penetration %.5f m\n",
              off.final_error, on.final_error, on.max_self_force, on.worst_penetration);
  EXPECT_LT(off.final_error, 0.05);                     // through each other (a tracking compromise of ~2 cm each)
  EXPECT_GT(on.max_self_force, 1.0);                     // the arms push on each other
  EXPECT_GT(on.final_error, off.final_error + 0.04);     // the goals cross by 8 cm: stopped short
  EXPECT_LT(on.worst_penetration, 0.005);
}

// Balance rows in the World (physics.balance_rows, thesis 3.3.2.1, Fig. 4.22 as a World): the actor
// leans far forward (pelvis 25 cm, head 40 cm, hands 60 cm ahead of the feet). Without the rows the CoM's
// projection leaves the support polygon of the feet; with them it stays inside (to the solver's
// first-order tolerance), the pelvis and head giving up part of their targets. The row holds the CoM in
// the support ellipse; with the thesis's enclosing ellipse the CoM may still leave the polygon near its
// corners, so this test uses the inscribed one (physics.balance_ellipse: inscribed).
TEST(WorldPhysics, BalanceRowsKeepALeaningMannequinsCoMOverItsFeet) {
  const auto lean = [](bool rows) {
    std::vector<MannequinSetup> setups;
    setups.push_back(actorSetup("operator", ""));
    SimConfig cfg = physicsConfigOfScene("bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n");
    cfg.physics.balance_rows = rows;
    cfg.physics.balance.inscribed = true;  // the row's ellipse inside the polygon (the thesis's encloses it)
    World w(std::move(setups), cfg);
    const math::SE3 base = placed(0, 0, 0);
    std::map<std::string, math::Vector3> from, to;
    const std::map<std::string, double> ahead{{"pelvis", 0.25}, {"head", 0.40}, {"hand_l", 0.60}, {"hand_r", 0.60}};
    for (const auto& [b, dx] : ahead) {
      from[b] = standingFrame(base, b).p;
      to[b] = from[b] + math::Vector3(dx, 0, b == "pelvis" ? -0.05 : 0.0);
    }
    const auto feed = [&](double t) {
      std::map<std::string, math::Vector3> m;
      for (const auto& [b, p] : from) m[b] = p + smooth(t / 1.5) * (to.at(b) - p);
      w.addMocap(actorFrame(ns(t) + 1, base, m));
    };
    w.addMocap(actorFrame(0, base));
    w.anchor(0);
    double lowest = 1e9;
    EXPECT_TRUE(run(w, 0, 2.5, feed, [&](double t) {
      const double d = w.mannequinDiagnostics(0).balance_distance_m;
      if (t > 0.5 && std::isfinite(d)) lowest = std::min(lowest, d);
      return true;
    }));
    EXPECT_EQ(w.failedSteps(), 0u);
    return std::make_pair(lowest, w.controlFrames(0)[0].position_error);
  };
  const auto [free_d, free_err] = lean(false);
  const auto [held_d, held_err] = lean(true);
  std::printf("leaning forward: balance distance min %.4f m without balance rows (pelvis error %.3f m), %.4f m with "
              "them (pelvis error %.3f m)\n",
              free_d, free_err, held_d, held_err);
  EXPECT_LT(free_d, -0.02);   // the CoM leaves the support polygon
  EXPECT_GT(held_d, -0.005);  // kept over the feet (first-order prediction, recovery 0.1 m/s)
  EXPECT_GT(held_err, free_err);
}

// A scenario in the loop (World::setScenario, thesis 4.1.2): the right hand follows the capture (free)
// until the operator's trigger, then goes autonomously to a goal 45 cm in front of the chest while the
// actor stands still: the hand reaches the goal (the capture's hand stays 40 cm away from it), and the
// switch is velocity-continuous — the hand's speed never jumps between two steps.
TEST(WorldScenario, ATriggerSwitchesAFrameFromTheCaptureToAnAutonomousReach) {
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  World w(std::move(setups), SimConfig{});
  const math::Vector3 goal(0.45, -0.25, 1.2);
  w.setScenario(scenario::parseScenario(
      "scenario: reach\nmannequins:\n  - name: operator\n    frames: [hand_r]\ntriggers: [go]\ninitial: follow\n"
      "states:\n  - name: follow\n    modes: {hand_r: free}\n    transitions:\n      - {to: reach, name: go, when: {trigger: go}}\n"
      "  - name: reach\n    modes:\n      hand_r: {mode: autonomous, goal: {xyz: [0.45, -0.25, 1.2], rpy_deg: [0, 0, 0]}, duration_s: 1.0}\n",
      "reach.yaml"));
  ASSERT_NE(w.scenarioEngine(), nullptr);
  const math::SE3 base = placed(0, 0, 0);
  w.addMocap(actorFrame(0, base));
  w.anchor(0);
  ASSERT_TRUE(w.calibrated(0));
  const auto feed = [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base)); };
  ASSERT_TRUE(run(w, 0, 0.5, feed));
  EXPECT_EQ(w.scenarioEngine()->stateName(), "follow");
  const DrivenFrame& hand = w.controlFrames(0)[3];
  ASSERT_EQ(hand.frame, "hand_r");
  EXPECT_LT(hand.position_error, 0.02) << "free: the hand follows the capture";
  const math::Vector3 captured = hand.target.p;
  w.trigger("go");
  // the target the controller is given (DrivenFrame::target, the scenario's setpoint): its velocity
  // between steps, and how much that changes from one step to the next
  math::Vector3 prev = hand.target.p, prev_v = math::Vector3::Zero();
  double worst_dv = 0, top_speed = 0;
  bool first = true;
  ASSERT_TRUE(run(w, 0.5, 1.5, feed, [&](double) {
    const math::Vector3 v = (hand.target.p - prev) / w.config().step;
    if (!first) worst_dv = std::max(worst_dv, (v - prev_v).norm());
    top_speed = std::max(top_speed, v.norm());
    first = false;
    prev = hand.target.p;
    prev_v = v;
    return true;
  }));
  EXPECT_EQ(w.scenarioEngine()->stateName(), "reach");
  std::printf("scenario: hand %.4f m from the goal, the capture's hand %.3f m from it; target: top speed %.3f m/s, "
              "worst speed change %.5f m/s per step\n", (hand.actual.p - goal).norm(), (captured - goal).norm(), top_speed, worst_dv);
  EXPECT_GT((captured - goal).norm(), 0.3) << "the goal is not where the capture's hand is";
  EXPECT_LT((hand.actual.p - goal).norm(), 0.02) << "the hand reached the autonomous goal";
  // a minimum-jerk reach of d = 0.55 m in T = 1 s peaks at 1.875 d/T ≈ 1.03 m/s and accelerates at most
  // 5.77 d/T² ≈ 3.2 m/s², 3.2 mm/s per 1 ms step; a target that jumped to the goal would move 0.55 m in one
  // step (550 m/s)
  EXPECT_LT(top_speed, 1.875 * 0.56 / 1.0 + 0.05) << "m/s";
  EXPECT_LT(worst_dv, 5.77 * 0.56 / 1.0 * w.config().step * 1.5) << "m/s per step";
  EXPECT_EQ(w.scenarioUnappliedActions(), 0);
  // names the World lacks are refused
  EXPECT_THROW(w.setScenario(scenario::parseScenario("scenario: x\nmannequins:\n  - name: bob\n    frames: [hand_r]\ninitial: a\n"
                                                       "states:\n  - name: a\n    modes: {hand_r: free}\n", "x.yaml")),
               std::invalid_argument);
}

// A constrained mode drives the controller's virtual mechanism (thesis 4.1.1, World::setScenario): the
// right hand is guided on a prismatic axis through its standing pose (along its own z axis, the
// mechanism's orientation its own so only the line constrains it) while the actor's hand moves 6 cm along
// the axis (up) and 8 cm across it (forward). In 'guided' the controller runs the mechanism (enabled, its coordinate
// following the actor along the axis), the hand stays on the line; the entry action set_gains reaches the
// controller; the trigger 'free' disables the mechanism and the hand goes back to the capture.
TEST(WorldScenario, AConstrainedModeGuidesTheHandOnTheMechanismsAxisAndSetGainsReachesTheController) {
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  World w(std::move(setups), SimConfig{});
  const math::SE3 base = placed(0, 0, 0);
  const math::SE3 hand0 = standingFrame(base, "hand_r");
  const Eigen::Vector3d ypr = hand0.R.eulerAngles(2, 1, 0) * 180.0 / M_PI;  // R = Rz(yaw) Ry(pitch) Rx(roll)
  const math::Vector3 axis = hand0.R.col(2), across = hand0.R.col(0);
  char yaml[2048];
  std::snprintf(yaml, sizeof yaml,
                "scenario: guide\nmannequins:\n  - name: operator\n    frames: [hand_r]\ntriggers: [free]\ninitial: guided\n"
                "states:\n  - name: guided\n    modes:\n      hand_r:\n        mode: constrained\n        blend_s: 0.2\n"
                "        mechanism:\n          type: prismatic\n          origin: {xyz: [%.9f, %.9f, %.9f], rpy_deg: [%.9f, %.9f, %.9f]}\n"
                "          limits: [[-0.3, 0.3]]\n          stiffness: {rotation: 100, translation: 5000}\n"
                "          damping: {rotation: 2, translation: 100}\n"
                "    entry:\n      - set_gains: {frame: hand_r, stiffness: {rotation: 250, translation: 5000}}\n"
                "    transitions:\n      - {to: loose, when: {trigger: free}}\n"
                "  - name: loose\n    modes: {hand_r: free}\n",
                hand0.p.x(), hand0.p.y(), hand0.p.z(), ypr[2], ypr[1], ypr[0]);
  w.setScenario(scenario::parseScenario(yaml, "guide.yaml"));
  w.addMocap(actorFrame(0, base));
  w.anchor(0);
  ASSERT_TRUE(w.calibrated(0));
  const math::Vector3 moved = hand0.p + 0.06 * axis + 0.08 * across;
  const auto feed = [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base, {{"hand_r", hand0.p + smooth(t / 1.0) * (moved - hand0.p)}})); };
  const auto* cs = dynamic_cast<const ControllerStepper*>(&w.stepper(0));
  ASSERT_NE(cs, nullptr);
  const int c = cs->controllerFrame(3);
  const DrivenFrame& hand = w.controlFrames(0)[3];
  ASSERT_EQ(hand.frame, "hand_r");
  double worst_off_axis = 0;
  ASSERT_TRUE(run(w, 0, 2.0, feed, [&](double t) {
    const math::Vector3 d = hand.actual.p - hand0.p;
    if (t > 0.3) worst_off_axis = std::max(worst_off_axis, (d - d.dot(axis) * axis).norm());
    return true;
  }));
  EXPECT_EQ(w.scenarioEngine()->stateName(), "guided");
  const control::ControlFrameState& f = cs->controller().frame(c);
  EXPECT_TRUE(f.mechanism_enabled);
  EXPECT_STREQ(hand.mode, "constrained");
  const double s = cs->controller().mechanism(c).s()(0);
  const double along = (hand.actual.p - hand0.p).dot(axis);
  std::printf("guided: worst distance from the axis %.4f m (the actor's hand 0.08 m off it), mechanism at %.4f m, the hand "
              "%.4f m along the axis (the actor 0.06)\n", worst_off_axis, s, along);
  EXPECT_LT(worst_off_axis, 0.01);          // on the line, though the capture is 8 cm off it
  EXPECT_NEAR(s, 0.06, 0.015);               // the mechanism follows the actor along the free direction
  EXPECT_NEAR(along, 0.06, 0.015);
  // set_gains at the entry: the frame's own coupling has the new gains (weight 1: tracked)
  EXPECT_NEAR(f.stiffness(0), 250.0, 1e-9);  // mocap.yaml: 300, 6000
  EXPECT_NEAR(f.stiffness(3), 5000.0, 1e-9);
  EXPECT_EQ(w.scenarioUnappliedActions(), 0);
  // back to free: the mechanism is off and the hand goes to the capture, off the axis
  w.trigger("free");
  ASSERT_TRUE(run(w, 2.0, 1.5, feed));
  EXPECT_EQ(w.scenarioEngine()->stateName(), "loose");
  EXPECT_FALSE(cs->controller().frame(c).mechanism_enabled);
  EXPECT_STREQ(hand.mode, "free");
  EXPECT_LT((hand.actual.p - moved).norm(), 0.02);
}

// Guides on objects through the scenario (attach_guide / detach_guide, World::attachGuide): a 1 kg tray
// in the air, no one holding it, is kept level and at its height by a plane guide (its weight carried by the
// guide) and pushed sideways by 3 N slides in its plane; the trigger 'drop' detaches the guide and it falls.
// A scenario whose guide the World cannot apply (a curve, a hinged object) is refused naming its line.
TEST(WorldScenario, AttachGuideHoldsATrayLevelAndDetachGuideLetsItFall) {
  const char* scene =
      "bodies:\n  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n"
      "  - name: tray\n    movable: true\n    pose: {position: [0.8, 0.4, 1.0]}\n    mass: 1.0\n"
      "    inertia: [0.01, 0.02, 0.03]\n    shape: {type: box, size: [0.4, 0.3, 0.02]}\n"
      "  - name: door\n    movable: true\n    pose: {position: [2.0, 0, 1.0]}\n    mass: 10\n"
      "    hinge: {axis: [0, 0, 1], point: [2.0, 0.45, 0], limits_deg: [0, 90]}\n    shape: {type: box, size: [0.04, 0.9, 2.0]}\n";
  std::vector<MannequinSetup> setups;
  setups.push_back(actorSetup("operator", ""));
  World w(std::move(setups), physicsConfigOfScene(scene));
  const int tray = w.findObject("tray");
  ASSERT_GE(tray, 0);
  const std::string head = "scenario: tray\nmannequins:\n  - name: operator\n    frames: [hand_r]\n";
  const std::string objects = "objects: [{name: tray, values: [z, x]}, {name: door, values: [angle]}]\n";
  w.setScenario(scenario::parseScenario(
      head + objects + "triggers: [drop]\ninitial: level\nstates:\n  - name: level\n    modes: {hand_r: free}\n    entry:\n"
             "      - attach_guide: {object: tray, mechanism: {type: plane, origin: {xyz: [0.8, 0.4, 1.0]}}}\n"
             "    transitions:\n      - {to: fall, when: {trigger: drop}}\n"
             "  - name: fall\n    modes: {hand_r: free}\n    entry:\n      - detach_guide: {object: tray}\n"
             "    transitions:\n      - {to: down, when: {object: {name: tray, value: z, below: 0.9}}}\n"
             "  - name: down\n    modes: {hand_r: free}\n",
      "tray.yaml"));
  const math::SE3 base = placed(0, 0, 0);
  w.addMocap(actorFrame(0, base));
  w.anchor(0);
  const auto feed = [&](double t) { w.addMocap(actorFrame(ns(t) + 1, base)); };
  double worst_tilt = 0, worst_height = 0;
  w.object(tray).addForce(w.object(tray).pose().p, math::Vector3(3, 0, 0));
  ASSERT_TRUE(run(w, 0, 1.0, feed, [&](double t) {
    w.object(tray).addForce(w.object(tray).pose().p, math::Vector3(3, 0, 0));  // for the next step
    if (t > 0.01) {
      worst_tilt = std::max(worst_tilt, std::acos(std::clamp(w.object(tray).pose().R(2, 2), -1.0, 1.0)));
      worst_height = std::max(worst_height, std::abs(w.object(tray).pose().p.z() - 1.0));
    }
    return true;
  }));
  const GuideRows* g = w.guides();
  ASSERT_NE(g, nullptr);
  EXPECT_TRUE(g->guided(tray));
  const double slid = w.object(tray).pose().p.x() - 0.8;
  std::printf("guided tray: tilt %.2e rad, height off %.2e m, slid %.4f m in 1 s, guide force z %.4f N (m g = 9.81)\n",
              worst_tilt, worst_height, slid, g->force(tray).z());
  EXPECT_LT(worst_tilt, 1e-6);
  EXPECT_LT(worst_height, 1e-6);
  EXPECT_NEAR(slid, 3.0 * 0.05 / 1.0, 0.005);       // in its plane at F τ / m = 0.15 m/s (τ = 0.05 s)
  EXPECT_NEAR(g->force(tray).z(), 9.81, 0.01);      // the guide carries its weight
  EXPECT_EQ(w.scenarioUnappliedActions(), 0);
  w.trigger("drop");
  // the object value z (its frame origin's height) ends the fall: still above 0.9 m after 0.1 s at g τ
  // (0.49 m/s), below it after 0.5 s
  ASSERT_TRUE(run(w, 1.0, 0.1, feed));
  EXPECT_EQ(w.scenarioEngine()->stateName(), "fall");
  EXPECT_FALSE(g->guided(tray));
  EXPECT_GT(w.object(tray).pose().p.z(), 0.9);
  ASSERT_TRUE(run(w, 1.1, 0.4, feed));
  EXPECT_EQ(w.scenarioEngine()->stateName(), "down");
  EXPECT_LT(w.object(tray).pose().p.z(), 1.0 - 0.1);
  // guides the World cannot apply are refused at setScenario, naming the action's line
  const auto refused = [&](const std::string& action, const std::string& what) {
    try {
      w.setScenario(scenario::parseScenario(head + "objects: [tray, door]\ninitial: a\nstates:\n  - name: a\n    modes: {hand_r: free}\n    entry:\n" + action,
                                            "bad.yaml"));
      ADD_FAILURE() << "accepted: " << action;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("bad.yaml:"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused("      - attach_guide: {object: tray, mechanism: {type: curve, points: [[0, 0, 1], [1, 0, 1]]}}\n", "curve");
  refused("      - attach_guide: {object: door, mechanism: {type: prismatic}}\n", "hinged");
  refused("      - attach_guide: {object: tray, mechanism: {type: plane, normal_force: 5}}\n", "force");
  // values the World does not report: an angle of a free object, an unknown name
  for (const char* bad : {"objects: [{name: tray, values: [angle]}]\n", "objects: [{name: tray, values: [w]}]\n"}) {
    try {
      w.setScenario(scenario::parseScenario(head + bad + "initial: a\nstates:\n  - name: a\n    modes: {hand_r: free}\n", "bad.yaml"));
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("value '"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("'x', 'y', 'z'"), std::string::npos) << e.what();
    }
  }
}
