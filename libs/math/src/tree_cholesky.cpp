#include "mannequin/math/tree_cholesky.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mannequin::math {

TreeCholesky::TreeCholesky(std::vector<int> parent) : parent_(std::move(parent)) {
  const int n = size();
  start_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int i = 0; i < n; ++i) {
    const int p = parent_[static_cast<std::size_t>(i)];
    if (p < -1 || p >= i)
      throw std::invalid_argument("TreeCholesky: parent[" + std::to_string(i) + "] = " + std::to_string(p) +
                                  ", expected -1 <= parent[i] < i");
    for (int a = p; a != -1; a = parent_[static_cast<std::size_t>(a)]) anc_.push_back(a);
    start_[static_cast<std::size_t>(i) + 1] = static_cast<int>(anc_.size());
  }
  d_.setZero(n);
  d_inv_.setZero(n);
  l_.setZero(static_cast<Eigen::Index>(anc_.size()));
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
  const int* st = start_.data();
  const int* anc = anc_.data();
  double* d = d_.data();
  double* l = l_.data();
  // the pattern's entries of b (lower triangle: row k at k and at its ancestors)
  for (int k = 0; k < n; ++k) {
    d[k] = b(k, k);
    for (int t = st[k]; t < st[k + 1]; ++t) l[t] = b(k, anc[t]);
  }
  return factorInPlace();
}

int TreeCholesky::packedIndex(int k, int i) const {
  if (k < 0 || k >= size()) return -1;
  for (int t = start_[static_cast<std::size_t>(k)]; t < start_[static_cast<std::size_t>(k) + 1]; ++t)
    if (anc_[static_cast<std::size_t>(t)] == i) return t;
  return -1;
}

Eigen::ComputationInfo TreeCholesky::computePacked(const Eigen::Ref<const VectorX>& diagonal,
                                                   const Eigen::Ref<const VectorX>& lower) {
  if (diagonal.size() != size() || lower.size() != packedSize())
    throw std::invalid_argument("TreeCholesky::computePacked: " + std::to_string(diagonal.size()) + " diagonal and " +
                                std::to_string(lower.size()) + " lower entries, expected " + std::to_string(size()) +
                                " and " + std::to_string(packedSize()));
  d_ = diagonal;
  l_ = lower;
  return factorInPlace();
}

Eigen::ComputationInfo TreeCholesky::factorInPlace() {
  const int n = size();
  const int* st = start_.data();
  const int* anc = anc_.data();
  double* d = d_.data();
  double* l = l_.data();
  // RBDA Table 6.3 (LTL), from the leaves to the root: row k scaled by its pivot, then removed from
  // the rows of its ancestors (row i = anc(k)[t] spans anc(k)[t+1 ...], the tail of row k)
  for (int k = n - 1; k >= 0; --k) {
    if (!(d[k] > 0.0) || !std::isfinite(d[k])) {
      info_ = Eigen::NumericalIssue;
      return info_;
    }
    d[k] = std::sqrt(d[k]);
    d_inv_[k] = 1.0 / d[k];
    const int cnt = st[k + 1] - st[k];
    if (cnt == 0) continue;  // a root (l may be empty: no pointer arithmetic on it)
    double* lk = l + st[k];
    for (int t = 0; t < cnt; ++t) lk[t] *= d_inv_[k];
    for (int t = 0; t < cnt; ++t) {
      const int i = anc[st[k] + t];
      const double lki = lk[t];
      d[i] -= lki * lki;
      double* li = l + st[i];
      for (int u = 0; u < cnt - t - 1; ++u) li[u] -= lki * lk[t + 1 + u];
    }
  }
  info_ = Eigen::Success;
  return info_;
}

MatrixX TreeCholesky::matrixL() const {
  const int n = size();
  MatrixX L = MatrixX::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    L(k, k) = d_[k];
    for (int t = start_[static_cast<std::size_t>(k)]; t < start_[static_cast<std::size_t>(k) + 1]; ++t)
      L(k, anc_[static_cast<std::size_t>(t)]) = l_[t];
  }
  return L;
}

void TreeCholesky::halfSolveInPlace(Eigen::Ref<VectorX> x) const {
  // Lᵀ y = x, from the leaves: column k of Lᵀ is L_kk and L_ki at k's ancestors i
  const int* st = start_.data();
  const int* anc = anc_.data();
  const double* l = l_.data();
  double* xp = x.data();
  for (int k = size() - 1; k >= 0; --k) {
    if (xp[k] == 0.0) continue;
    const double yk = xp[k] * d_inv_[k];
    xp[k] = yk;
    for (int t = st[k]; t < st[k + 1]; ++t) xp[anc[t]] -= l[t] * yk;
  }
}

void TreeCholesky::solveInPlace(Eigen::Ref<VectorX> x) const {
  halfSolveInPlace(x);
  // L x = y, from the root: row k of L is L_kk and L_ki at k's ancestors i
  const int* st = start_.data();
  const int* anc = anc_.data();
  const double* l = l_.data();
  double* xp = x.data();
  const int n = size();
  for (int k = 0; k < n; ++k) {
    double s = xp[k];
    for (int t = st[k]; t < st[k + 1]; ++t) s -= l[t] * xp[anc[t]];
    xp[k] = s * d_inv_[k];
  }
}

void TreeCholesky::solveInPlace(MatrixX& x) const {
  for (Eigen::Index c = 0; c < x.cols(); ++c) solveInPlace(Eigen::Ref<VectorX>(x.col(c)));
}

}  // namespace mannequin::math
