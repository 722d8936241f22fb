#pragma once
/// \file projector.hpp
/// \brief b_a-weighted null-space projectors for internal control (2.21–2.25) and strict priorities
/// (2.74–2.80), with a preallocated workspace, and Royer's augmented impedance split (2.29–2.42).
///
/// For a task Jacobian J (m × n) and the joint friction b_a = W (SPD, here diagonal):
///   Π = I − W⁻¹Jᵀ(J W⁻¹ Jᵀ)⁺ J                                   (2.74, and 2.35 with K = b_a)
/// Πᵀ projects a joint torque into ker(J W⁻¹): J W⁻¹ Πᵀ Γ = 0 (2.75–2.76), so a torque Πᵀ Γ_low
/// does not move the task under the dynamics q̇ = W⁻¹Γ (2.77). Π is unique whatever generalised
/// inverse of G = J W⁻¹ Jᵀ is used, as long as it is a {1}-inverse (G G^g G = G): hence
/// - kLdlt: pivoted LDLᵀ of the m × m Gram matrix G, pivots below rank_tolerance·max pivot set to
///   zero (≈ 15 µs for m = 36, n = 43);
/// - kSvd: JacobiSVD of J W^{-1/2} (thesis 1.41), rank from σ² > rank_tolerance·σ_max² (≈ 10× slower;
///   kept as the reference and where the rank itself is wanted).
/// Both give the same projector when the rank gap is clear (tests/control/projector_test.cpp).
#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include "mannequin/control/first_order.hpp"

namespace mannequin::control {

enum class ProjectorMethod { kLdlt, kSvd };

/// "ldlt" / "svd".
const char* toString(ProjectorMethod method);

/// Workspace computing Πᵀ Γ for one Jacobian (rows × n) and diagonal weight W. No allocation in
/// compute()/projectTorque() once built.
class WeightedNullSpace {
 public:
  WeightedNullSpace() = default;
  /// \param rows task rows m (may be 0: then Π = I), \param n joint velocities,
  /// \param rank_tolerance relative threshold on the eigenvalues of J W⁻¹ Jᵀ (see file comment).
  WeightedNullSpace(int rows, int n, ProjectorMethod method, double rank_tolerance);

  /// Factorises for J (rows × n) and the diagonal of W⁻¹ (n, all > 0).
  void compute(const Eigen::Ref<const MatrixX>& J, const VectorX& w_inv);
  /// As compute(), with G = J W⁻¹ Jᵀ formed by the caller (rows × rows, lower triangle read; e.g. a
  /// leading block of the Gram of a larger Jacobian, built from its sparsity). The SVD method
  /// ignores G and computes as compute().
  void computeWithGram(const Eigen::Ref<const MatrixX>& J, const VectorX& w_inv, const Eigen::Ref<const MatrixX>& G);
  /// out = Πᵀ g, the torque g with its part acting on the task removed. out may alias g.
  void projectTorque(const VectorX& g, VectorX& out);
  /// Π as a dense n × n matrix (allocates; for tests and tools).
  MatrixX matrix();

  int rank() const { return rank_; }
  int rows() const { return rows_; }
  ProjectorMethod method() const { return method_; }

 private:
  int rows_ = 0, n_ = 0, rank_ = 0;
  ProjectorMethod method_ = ProjectorMethod::kLdlt;
  double tol_ = 1e-8;
  MatrixX J_;        // (rows × n) copy of the task Jacobian
  VectorX w_inv_;    // (n) diagonal of W⁻¹
  VectorX sqrt_w_inv_;
  MatrixX Js_;       // (rows × n) J W^{-1/2}
  MatrixX G_;        // (rows × rows) J W⁻¹ Jᵀ, lower triangle
  Eigen::LDLT<MatrixX> ldlt_;
  Eigen::JacobiSVD<MatrixX> svd_;
  void factorGram();  // ldlt_ of G_ and the rank
  VectorX y_, z_;    // (rows)
  VectorX t_;        // (n)
  VectorX r_;        // (rank ≤ rows) for the SVD path
};

/// The null-space projectors of every priority prefix of one task Jacobian from ONE factorisation.
/// J (rows × n) has its rows in priority order; G = J W⁻¹ Jᵀ. G = L D Lᵀ without pivoting (L unit lower
/// triangular): the factor of G's leading m × m block is then the leading part of G's, so the level
/// projectors (the rows of the levels above, 2.78–2.80) and the internal projector (all rows, 2.25)
/// share it. Semidefinite: row k's pivot d_k is the W⁻¹-norm² of the part of row k that the rows
/// before it do not explain (Gram–Schmidt in the W⁻¹ metric); when d_k ≤ rank_tolerance · max_{j ≤ k}
/// G_jj the row depends on the rows before it and is dropped (d_k = 0, column k of L = 0). With Q
/// the orthogonalised rows (row k: what rows < k do not explain of J's row k; 0 when dropped), J = L Q,
/// and Jᵀ L⁻ᵀ D⁺ L⁻¹ J W⁻¹ projects onto their span = J's row space, so Πᵀ g = g − Jᵀ L⁻ᵀ D⁺ L⁻¹ J W⁻¹ g is the projector of the file
/// comment (L⁻ᵀ D⁺ L⁻¹ is a {1}-inverse of the thresholded G). A drop decision depends on rows ≤ k
/// only, so it is the same for every prefix. m³/6 multiply–adds for the whole G, no allocation after
/// construction (tests/control/projector_test.cpp: against kLdlt and kSvd, prefixes, rank deficiency).
class PriorityGramFactor {
 public:
  PriorityGramFactor() = default;
  /// \param rows task rows (may be 0), \param n joint velocities, \param rank_tolerance in (0, 1).
  /// allow_avx2: the factorisation's column updates use AVX2 where the CPU has it (the same results, bit
  /// for bit: no fused multiply-add); false forces the SSE2 code (tests compare the two).
  PriorityGramFactor(int rows, int n, double rank_tolerance, bool allow_avx2 = true);
  /// Factorises G (rows × rows, lower triangle read).
  void compute(const Eigen::Ref<const MatrixX>& G);
  /// out = Πᵀ g for the task made of the first m rows of J (the J whose Gram was factorised; w_inv
  /// the diagonal of W⁻¹). out may alias g. m = 0: out = g.
  void projectTorque(const Eigen::Ref<const MatrixX>& J, const VectorX& w_inv, int m, const VectorX& g, VectorX& out);
  /// Rows kept (independent) among the first m.
  int rank(int m) const;
  int rows() const { return rows_; }

 private:
  int rows_ = 0, n_ = 0;
  double tol_ = 1e-8;
  bool avx2_ = false;
  MatrixX L_;      // (rows × rows) L below the diagonal (the diagonal and above: scratch)
  VectorX d_;     // (rows) pivots, 0 for dropped rows
  VectorX v_;     // (rows) the Schur column being eliminated
  VectorX y_;     // (rows)
  VectorX t_;     // (n)
};

/// Royer's augmented impedance (2.29–2.42) with K = b_a: N a basis of ker(J) (n × (n−r)) and the
/// internal Jacobian J_int = (Nᵀ K N)⁻¹ Nᵀ K (2.39). Then Π = N J_int (2.36) equals the weighted
/// projector above, and J b_a⁻¹ J_intᵀ = 0 (the off-diagonal block of 2.42 vanishes): the
/// internal and operational dynamics are decoupled. Allocates (SVD of J); not for the loop.
struct AugmentedImpedance {
  MatrixX N;      ///< (n × (n − rank)) orthonormal basis of ker(J)
  MatrixX J_int;  ///< ((n − rank) × n)
};
/// \param b_a_diag (n) diagonal of b_a (> 0). \param rank_tolerance relative on singular values of J.
AugmentedImpedance augmentedImpedance(const MatrixX& J, const VectorX& b_a_diag, double rank_tolerance);

}  // namespace mannequin::control
