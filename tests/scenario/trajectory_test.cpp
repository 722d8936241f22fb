// Minimum-jerk trajectories in R³×SO(3) and continuity blends: boundary values, straight-line origin,
// geodesic rotation, velocity against finite differences; velocity continuity of the engine's
// setpoints across mode switches (Fig. 4.5).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mannequin/control/virtual_mechanism.hpp"
#include "mannequin/scenario/engine.hpp"
#include "mannequin/scenario/trajectory.hpp"

using namespace mannequin::scenario;
using mannequin::math::expSO3;
using mannequin::math::logSO3;

namespace {

// world twist (ω, v) by a central difference of a sampled trajectory
template <typename F>
Vector6 centralTwist(const F& sample, double t, double h) {
  const Setpoint a = sample(t - h), b = sample(t + h);
  Vector6 V;
  V.head<3>() = logSO3(b.pose.R * a.pose.R.transpose()) / (2 * h);
  V.tail<3>() = (b.pose.p - a.pose.p) / (2 * h);
  return V;
}

const SE3 kStart(expSO3(Vector3(0.1, -0.2, 0.3)), Vector3(0.1, 0.2, 1.0));
const SE3 kGoal(expSO3(Vector3(-0.4, 0.9, 0.2)), Vector3(0.6, -0.3, 1.4));

}  // namespace

TEST(MinimumJerk, TimeLawBoundaryValues) {
  EXPECT_DOUBLE_EQ(minimumJerk(0), 0);
  EXPECT_DOUBLE_EQ(minimumJerk(1), 1);
  EXPECT_DOUBLE_EQ(minimumJerk(0.5), 0.5);
  EXPECT_DOUBLE_EQ(minimumJerkDot(0), 0);
  EXPECT_DOUBLE_EQ(minimumJerkDot(1), 0);
  EXPECT_DOUBLE_EQ(minimumJerkDDot(0), 0);
  EXPECT_DOUBLE_EQ(minimumJerkDDot(1), 0);
  EXPECT_DOUBLE_EQ(minimumJerkDot(0.5), 1.875);  // the peak speed of the law
  const double h = 1e-6;
  for (double tau = 0.05; tau < 1.0; tau += 0.05) {
    EXPECT_NEAR(minimumJerkDot(tau), (minimumJerk(tau + h) - minimumJerk(tau - h)) / (2 * h), 1e-7);
    EXPECT_NEAR(minimumJerkDDot(tau), (minimumJerkDot(tau + h) - minimumJerkDot(tau - h)) / (2 * h), 1e-6);
  }
}

TEST(MinimumJerk, FromRestBoundaryValuesAndPath) {
  const double T = 1.3;
  const MinimumJerkTrajectory traj(Setpoint{kStart, Vector6::Zero()}, kGoal, T);
  const Setpoint s0 = traj.sample(0), s1 = traj.sample(T), after = traj.sample(T + 1);
  EXPECT_TRUE(s0.pose.isApprox(kStart, 1e-12));
  EXPECT_TRUE(s1.pose.isApprox(kGoal, 1e-12));
  EXPECT_TRUE(after.pose.isApprox(kGoal, 1e-12));
  EXPECT_LT(s0.twist.norm(), 1e-12);
  EXPECT_LT(s1.twist.norm(), 1e-12);
  // zero acceleration at both ends: the twist grows like t² (|V(h)| = O(h²), not O(h))
  const double h = 1e-3;
  EXPECT_LT(traj.sample(h).twist.norm(), 30 * h * h * (kGoal.p - kStart.p).norm() / (T * T * T) * 2 +
                                             30 * h * h * logSO3(kStart.R.transpose() * kGoal.R).norm() / (T * T * T) * 2);
  EXPECT_LT(traj.sample(T - h).twist.norm(), 30 * h * h * (kGoal.p - kStart.p).norm() / (T * T * T) * 2 +
                                                 30 * h * h * logSO3(kStart.R.transpose() * kGoal.R).norm() / (T * T * T) * 2);
  // R³×SO(3): the origin on the straight segment with the law, the rotation on the geodesic with the same law
  const Vector3 axis = logSO3(kStart.R.transpose() * kGoal.R);
  for (double t = 0; t <= T; t += T / 17) {
    const double s = minimumJerk(t / T);
    const Setpoint sp = traj.sample(t);
    EXPECT_TRUE(sp.pose.p.isApprox(kStart.p + s * (kGoal.p - kStart.p), 1e-12)) << t;
    EXPECT_TRUE(sp.pose.R.isApprox(kStart.R * expSO3(s * axis), 1e-12)) << t;
  }
}

TEST(MinimumJerk, VelocityMatchesFiniteDifferences) {
  const double T = 0.9;
  Vector6 V0;
  V0 << 0.5, -0.3, 0.8, 0.4, 0.1, -0.6;  // a start in motion
  for (const Vector6& start_twist : {Vector6(Vector6::Zero()), V0}) {
    const MinimumJerkTrajectory traj(Setpoint{kStart, start_twist}, kGoal, T);
    EXPECT_TRUE(traj.sample(0).twist.isApprox(start_twist, 1e-12));
    EXPECT_TRUE(traj.sample(0).pose.isApprox(kStart, 1e-12));
    EXPECT_TRUE(traj.sample(T).pose.isApprox(kGoal, 1e-12));
    EXPECT_LT(traj.sample(T).twist.norm(), 1e-12);
    const auto f = [&](double t) { return traj.sample(t); };
    for (double t = 0.01; t < T - 0.01; t += 0.037) {
      const Vector6 fd = centralTwist(f, t, 1e-5);
      EXPECT_LT((fd - traj.sample(t).twist).norm(), 1e-6) << "t " << t << " fd " << fd.transpose() << " analytic "
                                                          << traj.sample(t).twist.transpose();
    }
  }
}

TEST(Blend, StartsOnTheOldSetpointEndsOnTheNewOne) {
  Setpoint from{kStart, Vector6::Zero()}, to{kGoal, Vector6::Zero()};
  from.twist << 0.2, 0.0, -0.4, 1.0, 0.0, 0.3;
  to.twist << 0.0, 0.1, 0.0, 0.0, 0.5, 0.0;
  const double T = 0.4;
  const Blend blend(from, to, T);
  // the new mode's setpoint moves on with its own constant twist
  const auto target = [&](double t) {
    Setpoint s;
    s.pose = SE3(expSO3(to.twist.head<3>() * t) * to.pose.R, to.pose.p + to.twist.tail<3>() * t);
    s.twist = to.twist;
    return s;
  };
  const auto f = [&](double t) { return blend.apply(t, target(t)); };
  EXPECT_TRUE(f(0).pose.isApprox(from.pose, 1e-12));
  EXPECT_TRUE(f(0).twist.isApprox(from.twist, 1e-12));
  EXPECT_TRUE(f(T).pose.isApprox(target(T).pose, 1e-12));
  EXPECT_TRUE(f(T).twist.isApprox(to.twist, 1e-12));
  EXPECT_FALSE(blend.active(T));
  for (double t = 0.005; t < T - 0.005; t += 0.013)
    EXPECT_LT((centralTwist(f, t, 1e-5) - f(t).twist).norm(), 1e-6) << t;
}

namespace {

// One frame driven by a mocap target moving at constant velocity; a trigger switches free → constrained
// (a prismatic axis 10 cm away, turned 90°) and later constrained → autonomous. Finite-difference
// velocities of the setpoint must not jump at the switches by more than the continuity trajectories'
// accelerations allow in one step.
const char* kSwitches = R"(scenario: switches
mannequins:
  - name: m
    frames: [hand]
triggers: [guide, go]
states:
  - name: free
    transitions:
      - {to: guided, when: {trigger: guide}}
  - name: guided
    modes:
      hand:
        mode: constrained
        blend_s: 0.3
        mechanism:
          type: prismatic
          origin: {xyz: [0, 0.1, 1.0], rpy_deg: [0, 90, 0]}
    transitions:
      - {to: away, when: {trigger: go}}
  - name: away
    modes:
      hand: {mode: autonomous, goal: {xyz: [0.3, 0.3, 1.5], rpy_deg: [0, 0, 45]}, duration_s: 0.5}
)";

}  // namespace

TEST(Continuity, SetpointVelocityContinuousAcrossSwitches) {
  const Scenario s = parseScenario(kSwitches, "switches.yaml");
  Engine engine(s);
  const double dt = 1e-3;
  const int switch1 = 200, switch2 = 600, steps = 1400;
  const Vector3 v_target(0.4, 0.0, 0.0);  // m/s
  const auto target = [&](int k) {
    return SE3(mannequin::math::Matrix3::Identity(), Vector3(-0.3, 0, 1.0) + v_target * (k * dt));
  };
  // allowed |ẍ| per step: 0 where the setpoint is affine in t (the free target; its projection on an axis)
  std::vector<double> acc(steps + 1, 0.0), acc_rot(steps + 1, 0.0);
  std::vector<Vector3> p;
  std::vector<mannequin::math::Matrix3> R;
  Vector3 offset_at_switch = Vector3::Zero();
  Observation o;
  o.frames.resize(1);
  for (int k = 0; k < steps; ++k) {
    o.time = k * dt;
    o.frames[0].target = o.frames[0].pose = target(k);
    o.triggers.clear();
    if (k == switch1) o.triggers.push_back({"guide", ""});
    if (k == switch2) o.triggers.push_back({"go", ""});
    const StepResult& r = engine.step(o);
    p.push_back(r.frames[0].setpoint.pose.p);
    R.push_back(r.frames[0].setpoint.pose.R);
    if (k == switch1) {
      ASSERT_EQ(engine.stateName(), "guided");
      // the blend the engine builds: from the setpoint now onto the target's projection on the axis
      const mannequin::control::VirtualMechanism mech(s.states[1].modes[0].mechanism->spec);
      Setpoint to{mech.poseAt(mech.project(target(k))), Vector6::Zero()};
      to.twist.tail<3>() = (to.pose.p - mech.poseAt(mech.project(target(k - 1))).p) / dt;
      offset_at_switch = r.frames[0].setpoint.pose.p - to.pose.p;
      const Blend blend(r.frames[0].setpoint, to, 0.3);
      const double a = blend.positionAccelerationBound().norm();
      // rotation: R = exp(r) R_new with R_new fixed, ω = Jl(r) ṙ, so |ω̇| ≤ |r̈| + ‖dJl/dr‖ |ṙ|² with
      // ‖Jl‖ ≤ 1, ‖dJl/dr‖ ≤ 1 and |ṙ| ≤ |r̈|max T
      const double ar = blend.rotationAccelerationBound().norm();
      EXPECT_GT(std::acos(std::clamp(((to.pose.R.transpose() * r.frames[0].setpoint.pose.R).trace() - 1) / 2, -1.0, 1.0)),
                1.5);  // the axis turns the frame by 90°
      for (int j = k; j <= k + 301; ++j) {
        acc[static_cast<std::size_t>(j)] = a;
        acc_rot[static_cast<std::size_t>(j)] = ar + (ar * 0.3) * (ar * 0.3);
      }
    }
    if (k == switch2) {
      ASSERT_EQ(engine.stateName(), "away");
      // the autonomous trajectory from the setpoint (pose and twist): its position part is this quintic
      const Quintic3 q(r.frames[0].setpoint.pose.p, r.frames[0].setpoint.twist.tail<3>(), Vector3::Zero(),
                       Vector3(0.3, 0.3, 1.5), Vector3::Zero(), Vector3::Zero(), 0.5);
      // its rotation starts at rest (the axis's orientation does not turn): the geodesic with the law,
      // |ω̇| = |log(R0ᵀR1)| |s''(τ)| / T² ≤ |log(R0ᵀR1)| (10/√3) / T²
      const double angle = logSO3(r.frames[0].setpoint.pose.R.transpose() * expSO3(Vector3(0, 0, M_PI / 4))).norm();
      for (int j = k; j <= k + 501; ++j) {
        acc[static_cast<std::size_t>(j)] = q.accelerationBound().norm();
        acc_rot[static_cast<std::size_t>(j)] = angle * (10 / std::sqrt(3.0)) / (0.5 * 0.5);
      }
    }
  }
  // without continuity the first switch would jump by the offset in one step
  EXPECT_GT(offset_at_switch.norm(), 0.09);
  double worst = 0;
  for (std::size_t k = 2; k < p.size(); ++k) {
    // (p_k − 2p_{k−1} + p_{k−2}) / dt = ẍ(ξ) dt for some ξ in [t_{k−2}, t_k]
    const double jump = ((p[k] - p[k - 1]) - (p[k - 1] - p[k - 2])).norm() / dt;
    EXPECT_LE(jump, std::max(acc[k], acc[k - 1]) * dt + 1e-9) << "step " << k;
    worst = std::max(worst, jump);
    const Vector3 w1 = logSO3(R[k] * R[k - 1].transpose()) / dt, w0 = logSO3(R[k - 1] * R[k - 2].transpose()) / dt;
    EXPECT_LE((w1 - w0).norm(), std::max(acc_rot[k], acc_rot[k - 1]) * dt + 1e-6) << "step " << k;
  }
  // the largest velocity change in one step is a small fraction of a jump onto the axis (offset / dt)
  EXPECT_LT(worst, 0.01 * offset_at_switch.norm() / dt);
  // the setpoint ends where each mode puts it: on the axis after the blend, at the goal after the trajectory
  EXPECT_NEAR(p[switch2 - 1].y(), 0.1, 1e-9);
  EXPECT_NEAR(p[switch2 - 1].z(), 1.0, 1e-9);
  EXPECT_TRUE(p.back().isApprox(Vector3(0.3, 0.3, 1.5), 1e-12));
}
