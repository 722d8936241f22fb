// Fig. 4.22 (thesis 4.3.2, balance of 3.3.2.1): a right-hand reach 1 m in front of the mannequin
// drives the CoM out of the support (d(q) < 0) without the balance row; with it, d(q) stays ≥ 0 to
// first order, the feet stay put and the hand gets as close as balance allows.
// Measured (through the ConstraintSolver, same as a scalar one-row LCP emulation): without the row
// min d_m = −0.115 m, min polygon −0.144 m, hand error 1e-6 m; with it min d_m ≥ −1e-6 m, hand error
// 0.049 m, λ ≈ 319 N, soles within 0.012 m, polygon −0.054 m (the thesis's ellipse encloses the
// polygon); inscribed: polygon ≥ −1e-6 m, hand error 0.083 m.
// The mannequin: male_50th, gravity off, soles held by stiff couplings (priority 0), pelvis free,
// the hand at priority 1; the support: the 8 sole corners under the initial feet, floor z = 0.
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "mannequin/constraints/balance.hpp"
#include "mannequin/constraints/solver.hpp"
#include "mannequin/constraints/system.hpp"
#include "mannequin/sim/mannequin_system.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "../common/mannequins.hpp"

using namespace mannequin;
using namespace mannequin::constraints;

namespace {
using mannequin::testing::male50;

control::ControlFrameConfig frame(const std::string& name, int priority, double k_rot, double k_lin) {
  control::ControlFrameConfig c;
  c.name = c.frame = name;
  c.priority = priority;
  c.stiffness << k_rot, k_rot, k_rot, k_lin, k_lin, k_lin;
  c.damping = 10 * 1e-3 * c.stiffness;  // k δt / B = 0.1
  return c;
}

struct Reach {
  double min_ellipse = 1e9;     ///< min over the steps of d(q) (3.22), m²
  double min_ellipse_m = 1e9;   ///< of d(q)/(2δ), m
  double min_polygon = 1e9;     ///< of the CoM's signed distance to the support polygon, m
  double hand_error = 0;        ///< final distance of the hand to its target, m
  double sole_error = 0;        ///< worst distance of a sole to its initial pose over the run, m
  double lambda = 0;            ///< final balance force (N along d_m)
  long failures = 0;
};

/// `balance`: with the balance row in the step's LCP; `inscribed`: the inscribed ellipse.
Reach reach(bool balance, bool inscribed, int steps = 3000) {
  const skeleton::Model& model = male50();
  const skeleton::VectorX q0 = skeleton::standingConfiguration(model);
  control::ControllerConfig cfg;
  cfg.gravity.setZero();
  cfg.internal.stiffness = 150;
  cfg.frames = {frame("sole_l", 0, 500, 5000), frame("sole_r", 0, 500, 5000), frame("hand_r", 1, 100, 2000)};
  control::Controller ctl(model, cfg, q0);

  skeleton::Data data0(model);
  skeleton::forwardKinematics(model, data0, q0);
  std::vector<Vector3> support;
  const double half = 0.5 * model.segments[static_cast<std::size_t>(model.segmentIndex("foot_l"))].length;
  for (const char* name : {"sole_l", "sole_r"})
    for (double sx : {-1.0, 1.0})
      for (double sy : {-1.0, 1.0})
        support.push_back(data0.oMf[static_cast<std::size_t>(model.frameIndex(name))].act(Vector3(sx * half, sy * 0.045, 0)));

  BalanceOptions options;
  options.inscribed = inscribed;
  BalanceRows rows(0, model, ctl.data(), options);
  EXPECT_TRUE(rows.setSupport(support));
  sim::MannequinSystem system(ctl);
  ConstraintSolver solver({&system});
  if (balance) solver.addProducer(&rows);

  const int hand = ctl.frameIndex("hand_r");
  math::SE3 target = ctl.frame(hand).pose;
  target.p += Vector3(1.0, 0.0, 0.3);  // 1 m in front, 0.3 m up
  ctl.setTarget(hand, target);

  Reach out;
  for (int k = 0; k < steps; ++k) {
    EXPECT_EQ(ctl.computeFreeMotion(), control::StepStatus::kOk);
    rows.evaluate();  // d at q_k (the producer evaluates it again in the solve)
    out.min_ellipse = std::min(out.min_ellipse, rows.state().distance.ellipse);
    out.min_ellipse_m = std::min(out.min_ellipse_m, rows.state().distance.ellipse_m);
    out.min_polygon = std::min(out.min_polygon, rows.state().distance.polygon_m);
    out.sole_error = std::max({out.sole_error, ctl.frame(0).positionError(), ctl.frame(1).positionError()});
    if (balance) solver.solve(cfg.dt);
    ctl.integrate();
  }
  out.hand_error = ctl.frame(hand).positionError();
  out.lambda = rows.state().lambda;
  out.failures = solver.failures();
  std::printf("balance %d inscribed %d: min d %.5f m2, min d_m %.5f m, min polygon %.5f m, hand error %.4f m, "
              "sole error %.5f m, lambda %.2f N\n",
              balance, inscribed, out.min_ellipse, out.min_ellipse_m, out.min_polygon, out.hand_error, out.sole_error,
              out.lambda);
  return out;
}
}  // namespace

TEST(BalanceReach, WithoutTheRowTheReachLosesBalance) {
  const Reach r = reach(false, false);
  EXPECT_LT(r.min_ellipse_m, -0.05);  // the CoM ends well outside the ellipse
  EXPECT_LT(r.min_polygon, -0.05);
  EXPECT_LT(r.hand_error, 1e-3);      // the hand reaches its target
}

TEST(BalanceReach, WithTheRowBalanceHolds) {
  const Reach r = reach(true, false);
  EXPECT_GE(r.min_ellipse_m, -1e-4);  // d(q) ≥ 0 to first order in δt (Fig. 4.22, blue)
  EXPECT_GT(r.lambda, 0.0);           // the row is active at the end: balance limits the reach
  EXPECT_GT(r.hand_error, 0.01);      // the target is out of balanced reach (without: < 1e-3)
  EXPECT_LT(r.hand_error, 0.2);       // but the hand went most of the way (from 1.04 m)
  EXPECT_LT(r.sole_error, 0.03);      // the soles' couplings hold the feet (gravity off: only springs)
  EXPECT_EQ(r.failures, 0);
}

TEST(BalanceReach, TheInscribedEllipseKeepsTheCoMOverThePolygon) {
  const Reach r = reach(true, true);
  EXPECT_GE(r.min_ellipse_m, -1e-4);
  EXPECT_GE(r.min_polygon, -1e-4);    // inscribed ellipse ⊂ polygon
  EXPECT_EQ(r.failures, 0);
}
