#pragma once
/// \file so3.hpp
/// \brief The rotation group SO(3) and its algebra so(3) (thesis 1.2.1.1).
///
/// A rotation vector ω ∈ R³ (axis × angle, radians) is the exponential coordinate of
/// R = exp([ω]) (Rodrigues, thesis 1.11). The angle of log() is in [0, π].
#include "mannequin/math/types.hpp"

namespace mannequin::math {

/// [ω]: the 3×3 skew-symmetric matrix with [ω] x = ω × x (thesis 1.4).
Matrix3 hat(const Vector3& w);

/// Inverse of hat: the vector of a skew-symmetric matrix (the antisymmetric part is taken).
Vector3 vee(const Matrix3& W);

/// exp([ω]) by Rodrigues' formula (thesis 1.11), exact near ‖ω‖ = 0 (Taylor series).
Matrix3 expSO3(const Vector3& w);

/// log(R): the rotation vector ω with ‖ω‖ ∈ [0, π] and exp([ω]) = R.
/// Accurate near 0 (series) and near π (from the symmetric part of R). At exactly π the
/// two opposite vectors are both valid; the one with a positive largest component is returned.
/// \pre R is a rotation matrix (orthonormal, det +1) to within ~1e-9.
Vector3 logSO3(const Matrix3& R);

/// Right Jacobian of SO(3): d/dt exp(ω) = exp(ω) [Jr(ω) ω̇] (body angular velocity).
Matrix3 rightJacobianSO3(const Vector3& w);
/// Inverse of the right Jacobian: ω̇ = Jr(ω)⁻¹ Ω_body. Singular at ‖ω‖ = 2π only.
Matrix3 rightJacobianInverseSO3(const Vector3& w);
/// Left Jacobian of SO(3): d/dt exp(ω) = [Jl(ω) ω̇] exp(ω) (spatial angular velocity).
/// Also the matrix V of the SE(3) exponential: exp(ω, v).p = Jl(ω) v.
Matrix3 leftJacobianSO3(const Vector3& w);
/// Inverse of the left Jacobian.
Matrix3 leftJacobianInverseSO3(const Vector3& w);

/// Projects a near-rotation matrix onto SO(3) (polar decomposition by SVD), for use after
/// accumulated round-off; returns identity for a matrix with non-finite entries.
Matrix3 orthonormalize(const Matrix3& R);

/// True when R is orthonormal with det +1 within tol (max-abs error of RᵀR − I).
bool isRotation(const Matrix3& R, double tol = 1e-9);

}  // namespace mannequin::math
