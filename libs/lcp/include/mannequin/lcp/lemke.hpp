#pragma once
/// \file lemke.hpp
/// \brief Lemke's complementary pivoting (thesis 3.1.2, Algorithm 4) with the
/// lexicographic ratio test, so degenerate problems do not cycle.
///
/// Works on w − M z − d z₀ = q. Two forms of the same pivoting rules (same path up to rounding):
/// - product form (default): B⁻¹ is kept as the product of the pivots' elementary (eta) matrices;
///   a pivot costs O(n·k) after k pivots (the entering column B⁻¹A_j, one column of M), so a
///   path of a few tens of pivots on a large, mostly inactive problem costs little; when the eta
///   file is full (about n pivots) the attempt restarts in the dense form;
/// - dense: the tableau stores the n+1 non-basic columns (n×(n+1), column-major) and is updated
///   in place by a rank-one exchange at each pivot, O(n²) per pivot.
/// Both use the workspace's tableau buffer (etas in its columns); nothing is allocated once the workspace has the right size (the overload writing into a
/// caller's LcpResult allocates nothing at all once it has run on size n). For a copositive-plus
/// M (e.g. symmetric positive semidefinite) ray termination proves the LCP has no solution.
#include <cstdint>
#include <vector>

#include "mannequin/lcp/lcp.hpp"

namespace mannequin::lcp {

/// Options of solveLemke.
struct LemkeOptions {
  /// Maximum number of pivots; 0 means 100·n + 1000.
  int max_pivots = 0;
  /// A column entry t may be a pivot only if t > pivot_tolerance · max(‖column‖∞, scale),
  /// scale being max(‖M‖max, ‖d‖∞).
  double pivot_tolerance = 1e-12;
  /// Relative tolerance under which two ratios count as tied (lexicographic rule).
  double tie_tolerance = 1e-12;
  /// Covering vector d (n entries, all > 0). Empty means d = 1.
  Eigen::VectorXd covering;
  /// Extra runs when a run ends on a ray or fails the residual check (rank-deficient M can
  /// make a path numerically unstable): odd retries change the pivot tolerance (×100, then
  /// ×0.01), even ones perturb the covering vector (another path). A genuine ray
  /// termination is still reported as NoSolution.
  int retries = 3;
  /// A ray met after a pivot with |pivot| < unreliable_pivot · ‖column‖∞ is reported as
  /// NumericalFailure rather than NoSolution.
  double unreliable_pivot = 1e-9;
  /// Iterative-refinement steps applied to the final basic solution.
  int refinement_steps = 2;
  /// A final answer is reported Solved only if both relative residuals are ≤ this.
  double check_tolerance = 1e-9;
  /// Product form of B⁻¹ (eta file) instead of the dense tableau (see the file comment).
  bool product_form = true;
  /// Product form: at most this many etas before the restart in the dense form (0: as many as the
  /// workspace's n×(n+1) buffer holds, ≈ n).
  int max_etas = 0;
};

/// Pre-sized storage for solveLemke. Its buffers only grow: reserve(capacity) once and every later
/// problem of size n ≤ capacity uses their leading blocks without allocating.
class LemkeWorkspace {
 public:
  LemkeWorkspace() = default;
  explicit LemkeWorkspace(Index n) { resize(n); }
  /// Allocates for problems of any size ≤ capacity (nothing when already that large).
  void reserve(Index capacity);
  /// Prepares for a problem of size n (allocates only when n exceeds the capacity).
  void resize(Index n);
  Index size() const { return n_; }
  Index capacity() const { return capacity_; }
  /// The basis of the last Solved answer (n flags, 1: z_i basic — positive, or zero on a degenerate
  /// vertex): the guess to give solveLemkeWarm for a nearby problem. All 0 after the trivial answer.
  const std::uint8_t* basis() const { return basis_.data(); }

  // internal state, public so the solver is a free function (do not modify)
  Index n_ = -1;
  Index capacity_ = -1;
  // buffers are capacity-sized; the solver uses their leading n (n+1) rows/columns
  Eigen::MatrixXd tableau_;  // n×(n+1), B⁻¹ times the non-basic columns of [I, −M, −d]; product
                             // form: eta columns from the left, B⁻¹ rows of tied rows from the right
  Eigen::VectorXd rhs_;      // n, B⁻¹ q: values of the basic variables
  Eigen::VectorXd col_;      // n, pivot column copy
  Eigen::VectorXd row_;      // n+1, pivot row copy
  Eigen::VectorXd cover_;    // n, covering vector
  Eigen::VectorXd resid_;    // n, refinement residual
  Eigen::VectorXd delta_;    // n, refinement correction
  std::vector<int> basic_;     // n, variable basic in each row
  std::vector<int> nonbasic_;  // n+1, variable in each tableau column
  std::vector<int> where_;     // 2n+1, row (≥ 0) or −(column+1) of each variable
  std::vector<int> ties_;      // candidate rows of the ratio test
  std::vector<int> keep_;      // scratch for the lexicographic filter
  std::vector<int> eta_row_;   // product form: pivot row of each eta column
  std::vector<int> tie_col_;   // product form: tableau column holding row i's B⁻¹ row (−1: none)
  LcpResult retry_;            // result of a retry run (the in-place solve swaps it in)
  // warm start (solveLemkeWarm; the guessed basis's principal block is factorised in the tableau's buffer)
  std::vector<int> warm_idx_;  // k, indices of the guessed basic z's
  std::vector<int> warm_perm_; // k, row permutation of the LU
  std::vector<std::uint8_t> basis_;  // n, basis() (capacity-sized)
};

/// M known by its action, for problems whose M is a product (e.g. a Delassus matrix R b⁻¹ Rᵀ) that
/// need not be formed: the product form only reads the columns of the variables that enter the basis.
class LcpMatrixOperator {
 public:
  virtual ~LcpMatrixOperator() = default;
  virtual Index size() const = 0;
  /// out (n entries) = column j of M.
  virtual void column(Index j, Eigen::Ref<Eigen::VectorXd> out) const = 0;
  /// out (n entries) = M z.
  virtual void multiply(const VectorView& z, Eigen::Ref<Eigen::VectorXd> out) const = 0;
  /// max |M_ij| (the pivot tolerance's scale).
  virtual double maxAbs() const = 0;
  /// out (k×k) = M restricted to rows and columns idx[0..k) (a principal block). The default reads
  /// k columns; an operator with structure may do better. `scratch` has n entries.
  virtual void principal(const int* idx, Index k, Eigen::Ref<Eigen::MatrixXd> out,
                         Eigen::Ref<Eigen::VectorXd> scratch) const {
    for (Index c = 0; c < k; ++c) {
      column(idx[c], scratch);
      for (Index r = 0; r < k; ++r) out(r, c) = scratch[idx[r]];
    }
  }
};

/// Solves 0 ≤ M z + q ⊥ z ≥ 0 (M n×n, q n) by Lemke's method.
/// Returns Solved, NoSolution (ray termination), PivotLimit, Invalid (bad sizes, NaN/Inf,
/// non-positive covering vector) or NumericalFailure (final residual check failed).
LcpResult solveLemke(const LcpProblem& problem, LemkeWorkspace& workspace,
                     const LemkeOptions& options = {});

/// Same, written into `result` and returning its status. No heap allocation once `result` and the
/// workspace have held a problem of this size (options.covering empty or of size n): the form for a
/// real-time loop.
LcpStatus solveLemke(const LcpProblem& problem, LemkeWorkspace& workspace, const LemkeOptions& options,
                     LcpResult& result);

/// The capacity path: M (n×n) and q (n) are views (typically leading blocks of capacity-sized
/// buffers); the answer goes to the first n entries of result.z and result.w, which must hold at
/// least n entries (result.reserve(capacity); otherwise Invalid). No heap allocation once
/// workspace.reserve(capacity) and result.reserve(capacity) have run, for every n ≤ capacity.
LcpStatus solveLemke(const MatrixView& M, const VectorView& q, LemkeWorkspace& workspace,
                     const LemkeOptions& options, LcpResult& result);
/// The capacity path with M given by an operator (same contract). M's entries are not checked for
/// NaN/Inf (the caller's); q is. The dense form (product_form off, or a full eta file) reads every
/// column of M.
LcpStatus solveLemke(const LcpMatrixOperator& M, const VectorView& q, LemkeWorkspace& workspace,
                     const LemkeOptions& options, LcpResult& result);

/// Warm start from a guessed basis, e.g. the previous step's answer's (LemkeWorkspace::basis()):
/// `basic` (n flags, nonzero: z_i basic). The guess is tried first — z_B = −M_BB⁻¹ q_B (LU with partial pivoting of the
/// principal block), z_N = 0 — and is the answer (0 pivots, *warm = true) when it passes the same
/// final check as a Lemke answer (z ≥ 0, w = Mz + q ≥ 0, wᵀz = 0 to options.check_tolerance).
/// Otherwise (a wrong or singular guess, an empty one) Lemke runs from the start as solveLemke does.
/// For a problem with several solutions (redundant contacts), the guess picks the one nearest the
/// previous answer's structure. Same allocation contract as the capacity path.
LcpStatus solveLemkeWarm(const LcpMatrixOperator& M, const VectorView& q, const std::uint8_t* basic,
                         LemkeWorkspace& workspace, const LemkeOptions& options, LcpResult& result,
                         bool* warm = nullptr);
/// The same with a second guess (may be null), tried when the first fails and before Lemke: e.g. the
/// first guess with the degenerate choices a caller knows to be two-sided made the other way.
LcpStatus solveLemkeWarm(const LcpMatrixOperator& M, const VectorView& q, const std::uint8_t* basic,
                         const std::uint8_t* second, LemkeWorkspace& workspace, const LemkeOptions& options,
                         LcpResult& result, bool* warm = nullptr);

}  // namespace mannequin::lcp
