#pragma once
/// \file lcp.hpp
/// \brief Linear complementarity problem data, results and residuals (thesis 3.1.2,
/// definition 3.1.1): find z such that w = M z + q, z ≥ 0, w ≥ 0, wᵀz = 0.
#include <Eigen/Dense>

namespace mannequin::lcp {

using Index = Eigen::Index;

/// Outcome of a solve. Every solver returns one of these; none throws.
enum class LcpStatus {
  Solved,            ///< z ≥ 0, w ≥ 0, wᵀz = 0 hold to the checked tolerance
  NoSolution,        ///< ray termination (Lemke) or dual unboundedness (structured): no solution
  PivotLimit,        ///< pivot or iteration budget exhausted before convergence
  Invalid,           ///< bad input: non-square M, size mismatch, NaN/Inf entries, bad options
  NumericalFailure,  ///< the solver finished but its answer failed the final residual check
};

/// Short lowercase name of a status ("solved", "no_solution", "pivot_limit", "invalid",
/// "numerical_failure").
const char* statusName(LcpStatus status);

/// Problem data 0 ≤ M z + q ⊥ z ≥ 0. M is n×n, q has n entries.
struct LcpProblem {
  Eigen::MatrixXd M;  ///< n×n
  Eigen::VectorXd q;  ///< n
};

/// Residuals of a candidate (z, w), all non-negative.
struct LcpResiduals {
  double max_neg_w = 0.0;        ///< max(0, max_i −w_i)
  double max_neg_z = 0.0;        ///< max(0, max_i −z_i)
  double complementarity = 0.0;  ///< |wᵀz|
  /// |wᵀz| / (1 + Σ_i |z_i| (|q_i| + |(Mz)_i|)): complementarity relative to the size of
  /// the terms it sums.
  double relative_complementarity = 0.0;
  /// max(max_neg_w, max_neg_z) / (1 + ‖q‖∞ + ‖Mz‖∞ + ‖z‖∞).
  double relative_sign = 0.0;
};

/// Result of any LCP solver. z and w have n entries when status is Solved; on other
/// statuses they hold the last iterate (finite) or are zero.
struct LcpResult {
  LcpStatus status = LcpStatus::Invalid;
  Eigen::VectorXd z;       ///< n, the complementary variable
  Eigen::VectorXd w;       ///< n, w = M z + q recomputed from the problem data
  int pivots = 0;          ///< pivots (Lemke), sweeps (PGS) or active-set steps (structured)
  LcpResiduals residuals;  ///< of (z, w) against the original data
  const char* message = "";  ///< static string explaining the status
  /// Capacity path: sizes z and w to `capacity` entries once, so that the solvers' view overloads
  /// (M, q given as blocks of capacity-sized buffers) write the first n ≤ capacity entries without
  /// allocating; entries past n are left untouched.
  void reserve(Index capacity) {
    if (z.size() < capacity) z.setZero(capacity);
    if (w.size() < capacity) w.setZero(capacity);
  }
};

/// Read-only views of M (n×n) and q (n): a whole matrix or a block of a larger, capacity-sized one
/// (no copy either way).
using MatrixView = Eigen::Ref<const Eigen::MatrixXd>;
using VectorView = Eigen::Ref<const Eigen::VectorXd>;

/// Checks M square, q of matching size, all entries finite. Returns nullptr when valid,
/// otherwise a static message.
const char* validate(const LcpProblem& problem);
/// Same checks on views.
const char* validate(const MatrixView& M, const VectorView& q);

/// Residuals of z (n) against q (n); w (n) must already equal M z + q.
LcpResiduals computeResiduals(const VectorView& q, const VectorView& z, const VectorView& w);

/// True when both relative residuals are at most tol.
inline bool isComplementary(const LcpResiduals& r, double tol) {
  return r.relative_complementarity <= tol && r.relative_sign <= tol;
}

}  // namespace mannequin::lcp
