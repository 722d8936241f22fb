#include "mannequin/math/pinv.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <stdexcept>
#include <string>

namespace mannequin::math {

MatrixX pseudoInverse(const MatrixX& J, double rank_tol, int* rank) {
  // J = U diag(σ) Vᵀ  →  J⁺ = V diag(1/σ for σ > tol) Uᵀ (thesis 1.41)
  Eigen::JacobiSVD<MatrixX> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const auto& s = svd.singularValues();
  VectorX inv = VectorX::Zero(s.size());
  int r = 0;
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    if (s(i) > rank_tol) {
      inv(i) = 1.0 / s(i);
      ++r;
    }
  }
  if (rank) *rank = r;
  return svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose();
}

MatrixX pseudoInverseCOD(const MatrixX& J, double rank_tol, int* rank) {
  if (J.size() == 0) {
    if (rank) *rank = 0;
    return MatrixX::Zero(J.cols(), J.rows());
  }
  Eigen::CompleteOrthogonalDecomposition<MatrixX> cod(J.rows(), J.cols());
  // Eigen's threshold is relative to the largest pivot: convert the absolute one
  cod.compute(J);
  const double max_pivot = cod.maxPivot();
  if (max_pivot <= rank_tol) {
    if (rank) *rank = 0;
    return MatrixX::Zero(J.cols(), J.rows());
  }
  cod.setThreshold(rank_tol / max_pivot);
  if (rank) *rank = static_cast<int>(cod.rank());
  return cod.pseudoInverse();
}

MatrixX dampedPseudoInverse(const MatrixX& J, double lambda) {
  const double l2 = lambda * lambda;
  if (J.rows() <= J.cols()) {
    // Jᵀ (JJᵀ + λ²I)⁻¹
    MatrixX G = J * J.transpose();
    G.diagonal().array() += l2;
    return Eigen::LLT<MatrixX>(G).solve(J).transpose();
  }
  // (JᵀJ + λ²I)⁻¹ Jᵀ
  MatrixX G = J.transpose() * J;
  G.diagonal().array() += l2;
  return Eigen::LLT<MatrixX>(G).solve(J.transpose());
}

MatrixX dampedPseudoInverseSVD(const MatrixX& J, double lambda) {
  Eigen::JacobiSVD<MatrixX> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const auto& s = svd.singularValues();
  const VectorX f = s.array() / (s.array().square() + lambda * lambda);
  return svd.matrixV() * f.asDiagonal() * svd.matrixU().transpose();
}

MatrixX nullSpaceProjector(const MatrixX& J, double rank_tol) {
  return MatrixX::Identity(J.cols(), J.cols()) - pseudoInverse(J, rank_tol) * J;
}

MatrixX weightedNullSpaceProjector(const MatrixX& J, const MatrixX& W, double rank_tol) {
  const Eigen::Index n = J.cols();
  if (W.rows() != n || W.cols() != n) {
    throw std::invalid_argument("weightedNullSpaceProjector: weight matrix is " + std::to_string(W.rows()) +
                                "x" + std::to_string(W.cols()) + ", expected " + std::to_string(n) + "x" +
                                std::to_string(n) + " (the Jacobian's column count)");
  }
  Eigen::LLT<MatrixX> llt(W);
  if (llt.info() != Eigen::Success || !W.isApprox(W.transpose(), 1e-12)) {
    throw std::invalid_argument("weightedNullSpaceProjector: weight matrix is not symmetric positive definite");
  }
  // Π_W = I − W⁻¹Jᵀ (J W⁻¹ Jᵀ)⁺ J   (thesis 2.74)
  const MatrixX WinvJt = llt.solve(J.transpose());
  const MatrixX Lambda = J * WinvJt;
  return MatrixX::Identity(n, n) - WinvJt * pseudoInverse(Lambda, rank_tol) * J;
}

}  // namespace mannequin::math
