// Joint limits as unilateral constraints in the controller's step (thesis 3.7, Alg. 4): the limit
// holds to first order, λ ≥ 0 only at active limits (complementarity), ball components too, a
// coordinate past its limit comes back at the recovery speed, nothing changes far from the limits.
#include <gtest/gtest.h>

#include "mannequin/constraints/joint_limits.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/sim/mannequin_system.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

#include "male50_fixture.hpp"

using namespace mannequin;
using namespace mannequin::constraints;

namespace {
using testing_fixture::coordinate;
using testing_fixture::male50;
using testing_fixture::postureOnly;

/// Steps with the limits as stage 2 (or without), returns the trajectory of coordinate k.
std::vector<double> run(control::Controller& ctl, JointLimits* limits, int k, int steps) {
  std::vector<double> traj;
  for (int i = 0; i < steps; ++i) {
    EXPECT_EQ(ctl.computeFreeMotion(), control::StepStatus::kOk);
    if (limits != nullptr) {
      sim::MannequinSystem system(ctl);
      EXPECT_EQ(limits->apply(system, ctl.config().dt), lcp::LcpStatus::Solved);
    }
    ctl.integrate();
    traj.push_back(ctl.q()(k));
  }
  return traj;
}
}  // namespace

TEST(JointLimits, APostureTargetPastTheKneeLimitStopsAtTheLimit) {
  const int knee = coordinate("knee_r");
  ASSERT_EQ(male50().lower_limit(knee), 0.0);
  const skeleton::VectorX q0 = skeleton::standingConfiguration(male50());
  skeleton::VectorX qd = q0;
  qd(knee) = -0.5;  // hyperextension: 0.5 rad past the limit
  // without the limits the knee goes there
  control::Controller free(male50(), postureOnly(), q0);
  free.setPosture(qd);
  EXPECT_LT(run(free, nullptr, knee, 3000).back(), -0.4);
  // with them it stops at 0, pushed by λ > 0, to first order in δt
  control::Controller ctl(male50(), postureOnly(), q0);
  ctl.setPosture(qd);
  JointLimits limits(male50());
  const auto traj = run(ctl, &limits, knee, 3000);
  double lowest = 1.0;
  for (double v : traj) lowest = std::min(lowest, v);
  EXPECT_GT(lowest, -1e-9);
  EXPECT_NEAR(traj.back(), 0.0, 1e-9);
  ASSERT_EQ(limits.activeCount(), 1);
  // the standing posture has other coordinates at a limit (the left knee, straight): candidates with λ = 0
  const LimitRow* found = nullptr;
  for (const LimitRow& r : limits.rows())
    if (r.coordinate == knee) found = &r;
  ASSERT_NE(found, nullptr);
  const LimitRow& row = *found;
  EXPECT_FALSE(row.upper);
  // at rest λ balances the posture torque: k_int · 0.5 rad = 75 N·m
  EXPECT_NEAR(row.lambda, 150 * 0.5, 0.5);
  // the other coordinates moved as without limits (they were already at their posture)
  for (int k = 6; k < male50().nq; ++k)
    if (k != knee) {
      EXPECT_NEAR(ctl.q()(k), q0(k), 1e-6) << male50().coordinateNames()[k];
    }
}

TEST(JointLimits, ComplementarityOnlyActiveLimitsPush) {
  const int knee = coordinate("knee_r"), elbow = coordinate("elbow_l");
  const skeleton::VectorX q0 = skeleton::standingConfiguration(male50());
  skeleton::VectorX qd = q0;
  qd(knee) = -0.5;                                  // pulls into the limit
  qd(elbow) = male50().lower_limit(elbow) + 0.02;   // near its limit (a candidate) but inside
  control::Controller ctl(male50(), postureOnly(), q0);
  ctl.setPosture(qd);
  JointLimits limits(male50(), {0.05, 1.0, 4});
  run(ctl, &limits, knee, 2000);
  bool saw_elbow = false;
  for (const LimitRow& r : limits.rows()) {
    EXPECT_GE(r.lambda, 0.0);
    if (r.coordinate == elbow) {
      saw_elbow = true;
      EXPECT_EQ(r.lambda, 0.0) << "an inactive limit must not push";
      EXPECT_GT(r.distance, 0.0);
    }
    if (r.coordinate == knee) {
      EXPECT_GT(r.lambda, 1.0);
    }
  }
  EXPECT_TRUE(saw_elbow) << "the elbow is within the activation distance: it is a candidate row";
  EXPECT_NEAR(ctl.q()(elbow), qd(elbow), 1e-6);  // reached its posture, unhindered
}

TEST(JointLimits, BallJointComponentsAreLimitedThroughTheRightJacobian) {
  // the neck is a ball joint: its rotation vector component is limited, its velocity is ω (body)
  const auto names = male50().coordinateNames();
  int k = -1;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i].rfind("neck", 0) == 0 && std::isfinite(male50().upper_limit(static_cast<int>(i)))) {
      k = static_cast<int>(i);
      break;
    }
  ASSERT_GE(k, 0) << "no limited neck component";
  const skeleton::VectorX q0 = skeleton::standingConfiguration(male50());
  skeleton::VectorX qd = q0;
  qd(k) = male50().upper_limit(k) + 0.4;
  control::Controller ctl(male50(), postureOnly(), q0);
  ctl.setPosture(qd);
  JointLimits limits(male50());
  const auto traj = run(ctl, &limits, k, 3000);
  double highest = -10;
  for (double v : traj) highest = std::max(highest, v);
  // first order in δt per step (q̇ = Jr(q)⁻¹ω linearised at q_k): within 1e-5 rad of the limit
  EXPECT_LT(highest, male50().upper_limit(k) + 1e-5);
  EXPECT_NEAR(traj.back(), male50().upper_limit(k), 1e-5);
  EXPECT_GE(limits.activeCount(), 1);
}

TEST(JointLimits, ACoordinatePastItsLimitComesBackAtTheRecoverySpeed) {
  const int knee = coordinate("knee_r");
  skeleton::VectorX q0 = skeleton::standingConfiguration(male50());
  q0(knee) = -0.3;  // starts past the limit (e.g. a bad calibration)
  control::Controller ctl(male50(), postureOnly(), q0);
  skeleton::VectorX qd = q0;
  qd(knee) = -0.5;  // and the posture pulls further out
  ctl.setPosture(qd);
  JointLimits limits(male50(), {0.05, 1.0, 4});
  const auto traj = run(ctl, &limits, knee, 400);
  double prev = -0.3;
  for (double v : traj) {
    EXPECT_LE(v - prev, 1.0 * 1e-3 + 1e-12);  // never faster than 1 rad/s: no jump
    EXPECT_GE(v - prev, 0.0);                 // and always back towards the limit
    prev = v;
  }
  EXPECT_NEAR(traj[199], -0.1, 1e-6);  // 0.2 rad in 0.2 s
  EXPECT_NEAR(traj.back(), 0.0, 1e-9);
}

TEST(JointLimits, FarFromLimitsNothingChangesAndBadOptionsThrow) {
  const skeleton::VectorX q0 = skeleton::standingConfiguration(male50());
  skeleton::VectorX qd = q0;
  qd(coordinate("elbow_l")) = 1.0;
  control::Controller a(male50(), postureOnly(), q0), b(male50(), postureOnly(), q0);
  a.setPosture(qd);
  b.setPosture(qd);
  JointLimits limits(male50(), {0.0, 1.0, 4});
  for (int i = 0; i < 50; ++i) {
    a.step();
    b.computeFreeMotion();
    sim::MannequinSystem system(b);
    EXPECT_EQ(limits.apply(system, b.config().dt), lcp::LcpStatus::Solved);
    b.integrate();
  }
  EXPECT_EQ((a.q() - b.q()).norm(), 0.0);
  EXPECT_THROW(JointLimits(male50(), {-1.0, 1.0, 4}), std::invalid_argument);
  EXPECT_THROW(JointLimits(male50(), {0.05, NAN, 4}), std::invalid_argument);
}
