#pragma once
/// \file pinv.hpp
/// \brief Generalised inverses and null-space projectors (thesis 1.41, 2.74; paper Annex).
#include "mannequin/math/types.hpp"

namespace mannequin::math {

/// Moore–Penrose pseudo-inverse by SVD (thesis 1.40–1.41): singular values σ ≤ rank_tol
/// (ABSOLUTE threshold) are treated as zero.
/// \param[out] rank if non-null, the number of singular values above rank_tol.
MatrixX pseudoInverse(const MatrixX& J, double rank_tol, int* rank = nullptr);

/// Pseudo-inverse by complete orthogonal decomposition (cheaper than SVD, same result for a
/// well-separated rank). rank_tol is absolute on the pivots of the QR factorisation.
MatrixX pseudoInverseCOD(const MatrixX& J, double rank_tol, int* rank = nullptr);

/// Damped least-squares inverse J^{+λ} = Jᵀ(JJᵀ + λ²I)⁻¹ (paper Annex): singular values map
/// to σ/(σ² + λ²), so ‖J^{+λ}‖ ≤ 1/(2λ). Solved by Cholesky on the smaller Gram matrix.
/// \pre lambda > 0.
MatrixX dampedPseudoInverse(const MatrixX& J, double lambda);

/// Same by SVD, for reference and tests.
MatrixX dampedPseudoInverseSVD(const MatrixX& J, double lambda);

/// Null-space projector Π = I − J⁺J (n×n for J m×n): JΠ = 0, Π² = Π, Π = Πᵀ.
MatrixX nullSpaceProjector(const MatrixX& J, double rank_tol);

/// Null-space projector weighted by a symmetric positive-definite W (thesis 2.74):
/// Π_W = I − W⁻¹Jᵀ(JW⁻¹Jᵀ)⁺J. Then JΠ_W = 0, Π_W² = Π_W and J W⁻¹ Π_Wᵀ = 0 (dynamic
/// consistency, 2.75–2.76). rank_tol applies to the singular values of JW⁻¹Jᵀ.
/// \throws std::invalid_argument if W is not square of J's column count or not SPD.
MatrixX weightedNullSpaceProjector(const MatrixX& J, const MatrixX& W, double rank_tol);

}  // namespace mannequin::math
