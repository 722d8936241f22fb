#pragma once
/// \file se3.hpp
/// \brief Rigid transformations SE(3), twists se(3), adjoint maps (thesis 1.2.1.1, 3.42).
///
/// Conventions (the thesis's):
/// - H = [R p; 0 1] maps coordinates in the child frame to the parent frame: x_parent = R x + p.
///   Names carry the frames: `oMi` is the pose of frame i in the world (o), `pMc` of c in p.
/// - A twist is V = (ω, v) ∈ R⁶, ANGULAR PART FIRST (thesis 1.3): [V] = [[ω] v; 0 0].
///   A body twist satisfies Ḣ = H[V_body]; a spatial twist Ḣ = [V_spatial]H, V_spatial = Ad_H V_body.
/// - A wrench is W = (m, f) (moment first), dual to V so that the power is WᵀV.
#include "mannequin/math/so3.hpp"

namespace mannequin::math {

/// An element of SE(3): rotation R and translation p.
struct SE3 {
  Matrix3 R = Matrix3::Identity();  ///< rotation (3×3), child basis → parent basis
  Vector3 p = Vector3::Zero();      ///< origin of the child frame in the parent frame

  SE3() = default;
  SE3(const Matrix3& rotation, const Vector3& translation) : R(rotation), p(translation) {}

  static SE3 Identity() { return SE3(); }
  /// From a homogeneous 4×4 matrix (thesis 1.2).
  static SE3 fromMatrix(const Matrix4& H);
  /// Homogeneous 4×4 matrix.
  Matrix4 toMatrix() const;

  /// Composition: (aMb * bMc) = aMc.
  SE3 operator*(const SE3& other) const { return SE3(R * other.R, R * other.p + p); }
  /// Action on a point: x_parent = R x + p.
  Vector3 act(const Vector3& x) const { return R * x + p; }
  /// Inverse transform: bMa from aMb.
  SE3 inverse() const { return SE3(R.transpose(), -(R.transpose() * p)); }
  /// Action of the inverse on a point: Rᵀ (x − p).
  Vector3 actInv(const Vector3& x) const { return R.transpose() * (x - p); }

  bool isApprox(const SE3& other, double tol = 1e-12) const;
  bool allFinite() const { return R.allFinite() && p.allFinite(); }
};

/// [V]: the 4×4 matrix of a twist V = (ω, v) (thesis 1.3).
Matrix4 hat6(const Vector6& V);
/// Inverse of hat6.
Vector6 vee6(const Matrix4& Vhat);

/// exp(V) ∈ SE(3) in closed form (thesis 1.10; series near ω = 0).
SE3 expSE3(const Vector6& V);
/// log(H) = (ω, v) with ‖ω‖ ∈ [0, π]; exact near 0 and near π (see logSO3).
Vector6 logSE3(const SE3& H);

/// Ad_H = [R 0; [p]R R] (thesis 1.9): changes a twist's frame, [Ad_H V] = H[V]H⁻¹ (1.8).
Matrix6 Ad(const SE3& H);
/// Ad_H⁻¹ without forming the inverse first.
Matrix6 AdInv(const SE3& H);
/// Ad_H applied to a twist (cheaper than forming the matrix).
Vector6 actTwist(const SE3& H, const Vector6& V);
/// Coadjoint Ad*_H = Ad_{H⁻¹}ᵀ = [R [p]R; 0 R] (thesis 3.42): wrench in the child frame → parent frame.
Matrix6 coAd(const SE3& H);
/// ad_V = [[ω] 0; [v] [ω]] (thesis 1.5): [[V1],[V2]] = [ad_V1 V2] (1.6).
Matrix6 ad(const Vector6& V);

/// Interpolation in R³ × SO(3) (thesis 4.1.1, remark after Alg. 6): the origin moves on the
/// straight segment p(γ) = (1−γ)p0 + γp1 and the rotation on the SO(3) geodesic
/// R(γ) = R0 exp(γ log(R0ᵀR1)) (constant angular velocity). γ ∈ [0, 1].
/// Note: Alg. 6 mixes the logs of the absolute poses, which is a geodesic only when the start
/// is the identity; the relative form used here is the geodesic from any start.
SE3 interpolate(const SE3& H0, const SE3& H1, double gamma);
/// Geodesic of SE(3) itself (Alg. 6 in relative form): H0 exp(γ log(H0⁻¹H1)). Its origin
/// follows a helix, not a line; kept for comparison and for screw motions.
SE3 interpolateSE3(const SE3& H0, const SE3& H1, double gamma);

}  // namespace mannequin::math
