#pragma once
/// \file swing_twist.hpp
/// \brief Swing/twist decomposition of a ball joint's rotation and the distances to its limits
/// (thesis Annex D.2, eq. 28–98; limits as skeleton::BallLimit).
///
/// R (child in the joint placement frame "0", R = exp([q])) = R_s R_t about the unit twist axis t
/// (joint frame): z1 = R t,
///   θ_s = atan2(|t × z1|, t·z1) ∈ [0, π],  s = θ_s/sin θ_s (t × z1)          (34–35)
///   R_s = exp([s]),  R_t = R_sᵀ R = exp(θ_t [t]),  θ_t ∈ (−π, π] signed about t.
/// The thesis limits ‖r_t‖ with an ε-rounding at 0 (79); the SIGNED angle θ_t is smooth at 0, so no
/// rounding is needed. Jacobians are with respect to the ball's velocity ω = the child's BODY
/// angular velocity (R' = R exp(δt [ω])):
///   ds/dω  = [t] (f z1 tᵀ − g I) R [t],  g = θ_s/sin θ_s, f = (sin θ_s − θ_s cos θ_s)/sin³ θ_s  (61)
///            (series at θ_s → 0: g = 1 + θ²/6, f = 1/3 + 2θ²/15: smooth there — (70) is its θ = 0 value);
///   dθ_t/dω = tᵀ (I − Jr(s) ds/dω)   (97 with the signed angle; Jr the right Jacobian of SO(3));
///   dθ_s/dω = (t × Rᵀ e_θ)ᵀ,  e_θ = −sin θ_s t + cos θ_s (u × t), u = s/θ_s (bounded everywhere).
/// Near θ_s = π the decomposition is singular (‖ds/dω‖ ~ 1/sin θ_s, the twist is undefined at π):
/// beyond kSwingSingular the result is flagged `singular` and ds/dω, dθ_t/dω are zero (not used).
#include <Eigen/Dense>

#include "mannequin/skeleton/model.hpp"

namespace mannequin::constraints {

/// θ_s past which the swing/twist Jacobians are not computed (175°, rad).
inline constexpr double kSwingSingular = 175.0 * 3.14159265358979323846 / 180.0;

struct SwingTwist {
  double swing_angle = 0.0;                                   ///< θ_s (rad)
  Eigen::Vector3d swing = Eigen::Vector3d::Zero();            ///< s, joint placement frame, ⟂ t (rad)
  Eigen::Vector3d swing_dir = Eigen::Vector3d::UnitX();       ///< u (unit, ⟂ t), s = θ_s u
  Eigen::Matrix3d swing_jacobian = Eigen::Matrix3d::Zero();   ///< ds/dω
  Eigen::RowVector3d swing_angle_jacobian = Eigen::RowVector3d::Zero();  ///< dθ_s/dω
  double twist = 0.0;                                         ///< θ_t (rad)
  Eigen::RowVector3d twist_jacobian = Eigen::RowVector3d::Zero();        ///< dθ_t/dω
  bool singular = false;                                      ///< θ_s > kSwingSingular
};

/// Decomposes R about the unit axis t. `fallback` (unit, ⟂ t) is the swing direction used when
/// θ_s = π exactly and t × z1 vanishes. Never throws; no allocation. With `jacobians` false only the
/// values (θ_s, s, u, θ_t, singular) are computed — the same numbers — and the Jacobians stay zero.
SwingTwist swingTwist(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                      const Eigen::Vector3d& fallback = Eigen::Vector3d::UnitX(), bool jacobians = true);

/// R_s and R_t of a decomposition: R = swingRotation(st) * twistRotation(st, t).
Eigen::Matrix3d swingRotation(const SwingTwist& st);
Eigen::Matrix3d twistRotation(const SwingTwist& st, const Eigen::Vector3d& t);

/// Level of the swing ellipse at s: h(s) = ((s·e1 − c_x)/a)² + ((s·e2 − c_y)/b)² (≤ 1 inside), and
/// its gradient dh/ds (1 × 3, joint frame).
double ellipseLevel(const skeleton::BallLimit& l, const Eigen::Vector3d& s);
Eigen::RowVector3d ellipseGradient(const skeleton::BallLimit& l, const Eigen::Vector3d& s);
/// Distance from s = 0 to the ellipse along the unit direction u ⟂ t (rad; the ellipse contains 0).
double ellipseRadius(const skeleton::BallLimit& l, const Eigen::Vector3d& u);

/// A ball joint's limit distances at R, as rows for the LCP (rad; < 0 violated), with their rates
/// under ω (1 × 3).
struct BallLimitDistances {
  /// Swing: d_s = κ (1 − h(s)) (the thesis's 37 with d0 = 1, Q = diag(1/a², 1/b²) about the centre c),
  /// κ = 1/(2 uᵀQ(ρu − c)) > 0 at the ellipse radius ρ along u, so that d_s ≈ ρ − |s| (rad) near the
  /// boundary; J_s = −κ dh/ds ds/dω (κ frozen at R: same row up to a positive scale as the thesis's 62).
  /// Singular (θ_s > kSwingSingular): d_s = ρ − θ_s, J_s = −dθ_s/dω (push the swing back, radially).
  double swing = 0.0;
  Eigen::RowVector3d swing_jacobian = Eigen::RowVector3d::Zero();
  double swing_scale = 0.0;  ///< κ (0 when singular)
  /// How far s is past the ellipse along its ray (rad, ≥ 0): max(0, |s| − ρ).
  double swing_excess = 0.0;
  /// Twist: θ_t − lower and upper − θ_t with rates ±dθ_t/dω; not valid when singular.
  double twist_lower = 0.0, twist_upper = 0.0;
  Eigen::RowVector3d twist_jacobian = Eigen::RowVector3d::Zero();  ///< dθ_t/dω
  bool singular = false;
  SwingTwist st;
};

/// With `jacobians` false only the distances (and swing_scale, swing_excess, singular, st's values) are
/// computed — the same numbers — for callers that need no rows (a refinement's look-ahead, diagnostics).
BallLimitDistances ballLimitDistances(const skeleton::BallLimit& l, const Eigen::Matrix3d& R, bool jacobians = true);

}  // namespace mannequin::constraints
