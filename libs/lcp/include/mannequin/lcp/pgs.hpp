#pragma once
/// \file pgs.hpp
/// \brief Projected Gauss–Seidel with over-relaxation (PSOR) for 0 ≤ M z + q ⊥ z ≥ 0.
///
/// Sweep: z_i ← max(0, z_i − ω (q_i + M_i z) / M_ii). Converges for symmetric positive
/// (semi)definite M with positive diagonal and 0 < ω < 2; cheap per sweep (O(n²)) and the
/// usual choice for large contact sets, or as a fallback when Lemke fails.
#include "mannequin/lcp/lcp.hpp"

namespace mannequin::lcp {

/// Options of solvePgs.
struct PgsOptions {
  int max_iterations = 2000;  ///< sweeps before giving up (status PivotLimit)
  /// Stop when max_i M_ii |Δz_i| over a sweep ≤ tolerance · (1 + ‖q‖∞) and the final
  /// residual check passes.
  double tolerance = 1e-12;
  double relaxation = 1.0;  ///< ω in (0, 2)
  bool warm_start = false;  ///< start from the workspace's last z (same n) instead of 0
  /// Solved is reported only when both relative residuals are ≤ this.
  double check_tolerance = 1e-9;
};

/// Pre-sized storage for solvePgs (the transposed matrix for row access, the iterate). Its buffers
/// only grow (capacity-sized; the solver uses their leading n entries).
struct PgsWorkspace {
  PgsWorkspace() = default;
  explicit PgsWorkspace(Index n) { resize(n); }
  /// Allocates for every size ≤ capacity (nothing when already that large).
  void reserve(Index capacity);
  /// Prepares for size n: keeps the iterate when n is unchanged, else zeroes it; allocates only when
  /// n exceeds the capacity.
  void resize(Index n);
  Eigen::MatrixXd mt_;  ///< capacity², Mᵀ (leading n×n) so that row i of M is a contiguous column
  Eigen::VectorXd z_;   ///< capacity, current iterate (leading n; warm start)
  Eigen::VectorXd inv_diag_;  ///< capacity, 1 / M_ii (leading n)
  Index n_ = -1;        ///< size of the last problem
};

/// Solves the LCP (M n×n, q n) by projected Gauss–Seidel. Needs M_ii > 0 for every i
/// (otherwise Invalid). `pivots` in the result counts sweeps. Returns Solved, PivotLimit
/// (not converged within max_iterations; z is the last, finite iterate) or Invalid.
LcpResult solvePgs(const LcpProblem& problem, PgsWorkspace& workspace,
                   const PgsOptions& options = {});

/// The capacity path (as solveLemke's view overload): M, q views, answer in the first n entries of
/// result.z / result.w (at least n entries, else Invalid). No heap allocation once the workspace
/// and the result are reserved for n.
LcpStatus solvePgs(const MatrixView& M, const VectorView& q, PgsWorkspace& workspace,
                   const PgsOptions& options, LcpResult& result);

}  // namespace mannequin::lcp
