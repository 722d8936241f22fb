#pragma once
/// \file tree_cholesky.hpp
/// \brief Cholesky factorisation b = Lᵀ L of a symmetric positive-definite matrix with the sparsity
/// of a kinematic tree (Featherstone, *Rigid Body Dynamics Algorithms*, 2008, §6.5 "LTL").
///
/// The coordinates form a forest: parent[i] < i (or −1 for a root). b has the tree's sparsity when
/// b_ij ≠ 0 only for i = j or one of i, j an ancestor of the other — true of a joint-space inertia
/// and of the controller's apparent friction b = b_a + Σ Jᵀ B J (thesis 2.17), since a frame's
/// Jacobian J reaches only the coordinates supporting it. Factorised from the leaves towards the root,
/// L is lower triangular with the same sparsity (no fill-in): O(Σ_i depth(i)²) instead of n³/3, and
/// its solves are O(Σ_i depth(i)). A vector whose support is one branch (the coordinates supporting a
/// body, like a contact's Jacobian row) keeps that support through L⁻ᵀ.
///
/// Entries of b off the tree's pattern are not read (taken as zero); the strictly upper triangle is
/// never read. A chain (parent[i] = i − 1) gives the dense factorisation; no parents, a diagonal b.
#include <vector>

#include "mannequin/math/types.hpp"

namespace mannequin::math {

class TreeCholesky {
 public:
  TreeCholesky() = default;
  /// \throws std::invalid_argument unless −1 ≤ parent[i] < i for every i.
  explicit TreeCholesky(std::vector<int> parent);
  /// A chain of n coordinates (the dense case).
  static TreeCholesky dense(int n);

  int size() const { return static_cast<int>(parent_.size()); }
  const std::vector<int>& parents() const { return parent_; }

  /// Factorises b (size × size, lower triangle read). Allocates nothing once constructed.
  /// \return Success, or NumericalIssue when a pivot is not positive and finite (b not positive definite).
  Eigen::ComputationInfo compute(const Eigen::Ref<const MatrixX>& b);
  Eigen::ComputationInfo info() const { return info_; }

  /// b's entries on the tree's pattern, packed (for callers that assemble b by its pattern only):
  /// the diagonal b_kk (size()), and the strictly lower entries b_ki, i an ancestor of k, at
  /// packedIndex(k, i) of a vector of packedSize() entries (row k's ancestors nearest first).
  int packedSize() const { return static_cast<int>(anc_.size()); }
  /// Position of b_ki (i an ancestor of k) in the packed lower entries, or −1 when i is not one.
  int packedIndex(int k, int i) const;
  /// Same as compute() from the packed pattern (diagonal: size() entries, lower: packedSize()).
  /// \throws std::invalid_argument on a size mismatch.
  Eigen::ComputationInfo computePacked(const Eigen::Ref<const VectorX>& diagonal, const Eigen::Ref<const VectorX>& lower);

  /// The factor L (lower triangular, b = Lᵀ L) as a dense matrix (tests, logs: it is stored by rows
  /// of ancestors); entries off the tree's pattern are zero.
  MatrixX matrixL() const;

  /// x ← b⁻¹ x (a vector, or each column of a matrix).
  void solveInPlace(Eigen::Ref<VectorX> x) const;
  void solveInPlace(MatrixX& x) const;
  /// x ← L⁻ᵀ x, so that (L⁻ᵀ r)ᵀ (L⁻ᵀ s) = rᵀ b⁻¹ s: the half of b⁻¹ a Delassus matrix R b⁻¹ Rᵀ = XᵀX is
  /// built from. Zero entries are skipped (a branch's vector costs its branch's depth²).
  void halfSolveInPlace(Eigen::Ref<VectorX> x) const;

 private:
  std::vector<int> parent_;
  // row k of L: the diagonal d_[k] and, at [start_[k], start_[k + 1]), the entries L_k,i at k's
  // ancestors i = anc_[·], nearest first (so the ancestors of the t-th are the ones after it)
  std::vector<int> start_, anc_;
  VectorX d_, l_;
  VectorX d_inv_;  // 1 / d_: the solves multiply (a division's latency chains through a solve)
  Eigen::ComputationInfo info_ = Eigen::InvalidInput;
  Eigen::ComputationInfo factorInPlace();  // d_, l_ hold b's pattern: factorise them
};

}  // namespace mannequin::math
