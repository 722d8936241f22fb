#pragma once
/// \file structured.hpp
/// \brief Structured fast path for the contact LCP M = A Aᵀ (thesis 3.7 with
/// A = √δt J_c b^{-1/2}, n×m, m ≈ 42 ≪ n).
///
/// The LCP 0 ≤ A Aᵀ z + q ⊥ z ≥ 0 is exactly the optimality system of the strictly convex
/// QP  min ½‖x‖²  s.t.  A x + q ≥ 0  (x = Aᵀz, z the multipliers). It is solved in the
/// m-dimensional space by a dual active-set method (Goldfarb–Idnani with identity Hessian:
/// orthogonal J and triangular R updated by Givens rotations), optionally warm-started from
/// the previous solve's active set. w = A x + q and x = Aᵀz are unique, so they match
/// Lemke's; z itself may differ when rows of A are dependent.
#include <vector>

#include "mannequin/lcp/lcp.hpp"

namespace mannequin::lcp {

/// Problem data: A n×m, q n (M = A Aᵀ is never formed).
struct StructuredProblem {
  Eigen::MatrixXd A;  ///< n×m
  Eigen::VectorXd q;  ///< n
};

/// Options of solveStructured.
struct StructuredOptions {
  int max_iterations = 0;  ///< active-set steps; 0 means 10·(n + m) + 100
  /// A row whose component outside the active span is ≤ this · ‖row‖ is treated as
  /// dependent (no primal step).
  double dependence_tolerance = 1e-10;
  /// A row counts as violated when A_i x + q_i < −feasibility_tolerance · (1 + ‖q‖∞).
  double feasibility_tolerance = 1e-13;
  /// Try the previous solve's active constraints first (same n only).
  bool warm_start = true;
  /// Solved is reported only when both relative residuals are ≤ this.
  double check_tolerance = 1e-9;
};

/// Pre-sized storage for solveStructured; also keeps the last active set for warm starts. Its
/// buffers only grow (capacity-sized; the solver uses their leading blocks).
struct StructuredWorkspace {
  StructuredWorkspace() = default;
  StructuredWorkspace(Index n, Index m) { resize(n, m); }
  /// Allocates for every problem of at most n_capacity rows and m_capacity columns.
  void reserve(Index n_capacity, Index m_capacity);
  /// Prepares for n rows and m columns; keeps the active set when sizes are unchanged; allocates
  /// only beyond the capacity.
  void resize(Index n, Index m);
  Eigen::MatrixXd J_;   ///< m×m orthogonal factor
  Eigen::MatrixXd R_;   ///< m×m, upper-triangular in its leading active block
  Eigen::VectorXd x_;   ///< m, primal solution x = Aᵀz
  Eigen::VectorXd s_;   ///< n, slacks A x + q
  Eigen::VectorXd dir_; ///< m, primal step direction
  Eigen::VectorXd d_;   ///< m, Jᵀ a_p
  Eigen::VectorXd r_;   ///< m, dual step direction
  Eigen::VectorXd u_;   ///< m, multipliers of the active rows
  Eigen::VectorXd as_;  ///< n, A times the primal direction
  Eigen::VectorXd norms_;     ///< n, row norms of A
  std::vector<int> active_;   ///< active rows, in insertion order
  std::vector<int> previous_; ///< active rows of the last solve (warm start)
  std::vector<char> is_active_, hinted_;  ///< n flags
  Index n_ = -1, m_ = -1;
  Index n_cap_ = 0, m_cap_ = 0;
};

/// Solves 0 ≤ A Aᵀ z + q ⊥ z ≥ 0 (A n×m, q n). On return workspace.x_ holds x = Aᵀz.
/// Returns Solved, NoSolution (the constraints A x + q ≥ 0 are infeasible), PivotLimit,
/// Invalid or NumericalFailure.
LcpResult solveStructured(const StructuredProblem& problem, StructuredWorkspace& workspace,
                          const StructuredOptions& options = {});

/// The capacity path: A (n×m) and q (n) are views (blocks of capacity-sized buffers), the answer
/// goes to the first n entries of result.z / result.w (at least n entries, else Invalid). No heap
/// allocation once workspace.reserve(n_cap, m_cap) and result.reserve(n_cap) have run.
LcpStatus solveStructured(const MatrixView& A, const VectorView& q, StructuredWorkspace& workspace,
                          const StructuredOptions& options, LcpResult& result);

/// Factors a symmetric positive semidefinite M (n×n) as M ≈ A Aᵀ with A n×r (r = numerical
/// rank) by a symmetric eigendecomposition, dropping eigenvalues ≤ rank_tol · λ_max.
/// Returns nullptr on success, otherwise a static message (M not symmetric, an eigenvalue
/// < −rank_tol · λ_max so M is not PSD, NaN/Inf entries).
const char* factorPsd(const Eigen::MatrixXd& M, Eigen::MatrixXd& A, double rank_tol = 1e-12);

}  // namespace mannequin::lcp
