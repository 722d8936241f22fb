#include "mannequin/math/tree_cholesky.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mannequin::math {

TreeCholesky::TreeCholesky(std::vector<int> parent) : parent_(std::move(parent)) {
  const int n = size();
  for (int i = 0; i < n; ++i) {
    const int p = parent_[static_cast<std::size_t>(i)];
    if (p < -1 || p >= i)
      throw std::invalid_argument("TreeCholesky: parent[" + std::to_string(i) + "] = " + std::to_string(p) +
                                  ", expected -1 <= parent[i] < i");
  }
  L_.setZero(n, n);
}

TreeCholesky TreeCholesky::dense(int n) {
  if (n < 0) throw std::invalid_argument("TreeCholesky::dense: negative size");
  std::vector<int> p(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) p[static_cast<std::size_t>(i)] = i - 1;
  return TreeCholesky(std::move(p));
}

Eigen::ComputationInfo TreeCholesky::compute(const Eigen::Ref<const MatrixX>& b) {
  const int n = size();
  if (b.rows() != n || b.cols() != n)
    throw std::invalid_argument("TreeCholesky::compute: b is " + std::to_string(b.rows()) + "x" +
                                std::to_string(b.cols()) + ", expected " + std::to_string(n) + "x" + std::to_string(n));
  const int* lambda = parent_.data();
  // the pattern's entries of b (lower triangle: row k, columns k and its ancestors)
  for (int k = 0; k < n; ++k) {
    L_(k, k) = b(k, k);
    for (int i = lambda[k]; i != -1; i = lambda[i]) L_(k, i) = b(k, i);
  }
  // RBDA Table 6.3 (LTL): from the leaves to the root
  for (int k = n - 1; k >= 0; --k) {
    const double a = L_(k, k);
    if (!(a > 0.0) || !std::isfinite(a)) {
      info_ = Eigen::NumericalIssue;
      return info_;
    }
    const double d = std::sqrt(a);
    L_(k, k) = d;
    for (int i = lambda[k]; i != -1; i = lambda[i]) L_(k, i) /= d;
    for (int i = lambda[k]; i != -1; i = lambda[i]) {
      const double lki = L_(k, i);
      for (int j = i; j != -1; j = lambda[j]) L_(i, j) -= lki * L_(k, j);
    }
  }
  info_ = Eigen::Success;
  return info_;
}

void TreeCholesky::halfSolveInPlace(Eigen::Ref<VectorX> x) const {
  // Lᵀ y = x, from the leaves: column k of Lᵀ holds L_kk and L_ki at k's ancestors i
  const int* lambda = parent_.data();
  for (int k = size() - 1; k >= 0; --k) {
    if (x[k] == 0.0) continue;
    const double yk = x[k] / L_(k, k);
    x[k] = yk;
    for (int i = lambda[k]; i != -1; i = lambda[i]) x[i] -= L_(k, i) * yk;
  }
}

void TreeCholesky::solveInPlace(Eigen::Ref<VectorX> x) const {
  halfSolveInPlace(x);
  // L x = y, from the root: row k of L holds L_kk and L_ki at k's ancestors i
  const int* lambda = parent_.data();
  const int n = size();
  for (int k = 0; k < n; ++k) {
    double s = x[k];
    for (int i = lambda[k]; i != -1; i = lambda[i]) s -= L_(k, i) * x[i];
    x[k] = s / L_(k, k);
  }
}

void TreeCholesky::solveInPlace(MatrixX& x) const {
  for (Eigen::Index c = 0; c < x.cols(); ++c) solveInPlace(Eigen::Ref<VectorX>(x.col(c)));
}

}  // namespace mannequin::math
