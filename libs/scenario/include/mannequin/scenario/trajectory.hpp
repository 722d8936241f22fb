#pragma once
/// \file trajectory.hpp
/// \brief Autonomous trajectories and continuity at mode switches (thesis 4.1.1 Alg. 6 and the
/// R³×SO(3) remark after it, 4.1.2 Fig. 4.5).
///
/// Twists here are WORLD-frame (ω, v): ω the angular velocity in world axes (Ṙ = [ω]R), v = ṗ the
/// velocity of the frame's origin. Angular part first, like math::SE3's twists.
#include "mannequin/math/se3.hpp"

namespace mannequin::scenario {

using math::Matrix3;
using math::SE3;
using math::Vector3;
using math::Vector6;

/// The minimum-jerk time law s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ (τ = t/T clamped to [0, 1]) and its derivatives
/// with respect to τ.
double minimumJerk(double tau);
double minimumJerkDot(double tau);
double minimumJerkDDot(double tau);

/// A quintic polynomial per component from (x0, v0, a0) at t = 0 to (x1, v1, a1) at t = T; held at x1 after T.
class Quintic3 {
 public:
  Quintic3() = default;
  Quintic3(const Vector3& x0, const Vector3& v0, const Vector3& a0, const Vector3& x1, const Vector3& v1,
           const Vector3& a1, double T);
  void sample(double t, Vector3& x, Vector3& v, Vector3& a) const;
  double duration() const { return T_; }
  /// An upper bound of |ẍ_i(t)| over [0, T] per component, from the coefficients (no sampling).
  Vector3 accelerationBound() const;

 private:
  double T_ = 0;
  Eigen::Matrix<double, 3, 6> c_ = Eigen::Matrix<double, 3, 6>::Zero();  ///< x(t) = Σ c_k t^k
};

/// A setpoint: pose and world twist (ω, v).
struct Setpoint {
  SE3 pose;
  Vector6 twist = Vector6::Zero();
};

/// Minimum-jerk trajectory in R³×SO(3) from a start setpoint (pose and twist) to a goal pose reached at
/// rest after `duration`. With a start at rest, the origin moves on the straight segment with the
/// law s(τ) and the rotation on the geodesic R0 exp(s(τ) log(R0ᵀR1)) (the same law); a nonzero start
/// twist adds a quintic that starts with that twist and vanishes with its first two derivatives at T,
/// so the setpoint is velocity-continuous with what came before.
class MinimumJerkTrajectory {
 public:
  MinimumJerkTrajectory() = default;
  MinimumJerkTrajectory(const Setpoint& start, const SE3& goal, double duration);
  Setpoint sample(double t) const;  ///< held at the goal after the duration
  const SE3& goal() const { return goal_; }
  double duration() const { return T_; }

 private:
  SE3 start_, goal_;
  Vector3 axis_ = Vector3::Zero();  ///< log(R0ᵀR1)
  double T_ = 1;
  Quintic3 pos_, rot_;              ///< position; world rotation-vector residual
};

/// Continuity at a switch (Fig. 4.5): the new mode's own setpoint (mocap, its projection on a
/// mechanism...) may differ from the setpoint at the switch, in pose and twist. The blend adds to the new
/// mode's setpoint an offset e(t) (position) and a rotation exp(r(t)) (world) that start with the
/// difference, pose and twist, and vanish with their first two derivatives after `duration`:
///   p(t) = p_new(t) + e(t),  R(t) = exp(r(t)) R_new(t).
/// The setpoint is thus continuous in pose and velocity across the switch and ends on the new constraint.
class Blend {
 public:
  Blend() = default;
  /// `from` is the setpoint at the switch, `to` the new mode's setpoint at the same instant.
  Blend(const Setpoint& from, const Setpoint& to, double duration);
  /// The blended setpoint at time t after the switch, given the new mode's setpoint then.
  Setpoint apply(double t, const Setpoint& target) const;
  bool active(double t) const { return t < T_; }
  double duration() const { return T_; }
  /// Bounds of |ë| and |r̈| over the blend (for tests and checks; from the coefficients).
  Vector3 positionAccelerationBound() const { return e_.accelerationBound(); }
  Vector3 rotationAccelerationBound() const { return r_.accelerationBound(); }

 private:
  double T_ = 0;
  Quintic3 e_, r_;
};

}  // namespace mannequin::scenario
