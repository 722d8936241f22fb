#pragma once
/// \file first_order.hpp
/// \brief First-order (quasi-static) simulation pieces (thesis 2.2.1.1–2.2.1.2, Annex C):
/// the explicit Euler stability ratio (2.11) and allocation-free configuration-space updates.
///
/// The dynamics is b_a q̇ = Γ + Γ_gravity (2.4): no inertia, a symmetric positive-definite joint
/// viscous friction b_a. Explicit Euler (2.7) on a spring k with friction b gives
/// x_{k+1} = (1 − kδt/b) x_k (2.9), stable iff 0 < kδt/b < 2 (2.11).
#include "mannequin/skeleton/model.hpp"

namespace mannequin::control {

using math::Matrix3;
using math::MatrixX;
using math::Matrix6;
using math::Matrix6X;
using math::SE3;
using math::Vector3;
using math::Vector6;
using math::VectorX;

/// kδt/b of (2.11): the explicit Euler step of b ẋ = −k x is stable iff the ratio is in (0, 2),
/// and monotone (no overshoot) iff it is in (0, 1]. \pre b > 0.
inline double eulerStabilityRatio(double k, double b, double dt) { return k * dt / b; }

/// How a coupling measures x_d − x (2.12): kR3SO3 (default) as below, kSE3 the thesis's literal
/// log(H⁻¹H_d) ∈ se(3).
enum class CouplingError { kR3SO3, kSE3 };

/// Error of a coupling from frame H to frame H_d, in H's axes: e = (log(RᵀR_d), Rᵀ(p_d − p)).
/// The thesis writes x_d − x as log(H⁻¹H_d) (2.12); this is its R³ × SO(3) form (the split the
/// thesis keeps for interpolation, 4.1.1): equal to first order, but the translational part pulls
/// along the straight line to the target even for large rotation errors, where the se(3) log
/// would follow a helix. Consistent with body twists: ė = V_d − V to first order.
inline Vector6 couplingError(const SE3& H, const SE3& H_d) {
  Vector6 e;
  e.head<3>() = math::logSO3(H.R.transpose() * H_d.R);
  e.tail<3>() = H.R.transpose() * (H_d.p - H.p);
  return e;
}
/// Same, with the chosen form (kSE3: log(H⁻¹H_d)).
inline Vector6 couplingError(const SE3& H, const SE3& H_d, CouplingError form) {
  return form == CouplingError::kSE3 ? math::logSE3(H.inverse() * H_d) : couplingError(H, H_d);
}

/// q ⊕ v·dt on the configuration manifold, written into q_out (no allocation):
/// revolute q + v dt; ball log(exp(q) exp(v dt)); free flyer H exp(V dt) with V the body twist
/// (Crouch–Grossman order 1, Annex C). Same result as skeleton::integrate, which returns a new vector.
/// \pre q, q_out of size model.nq, v of size model.nv; q_out may alias q.
void integrateInPlace(const skeleton::Model& model, const VectorX& q, const VectorX& v, double dt, VectorX& q_out);

/// The v with integrate(q0, v, 1) = q1, written into v_out (no allocation); same as skeleton::difference.
/// Ball and free-flyer rotations give body-frame vectors log(R0ᵀR1).
void differenceInPlace(const skeleton::Model& model, const VectorX& q0, const VectorX& q1, VectorX& v_out);

}  // namespace mannequin::control
