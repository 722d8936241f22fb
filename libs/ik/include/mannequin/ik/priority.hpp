#pragma once
/// \file priority.hpp
/// \brief The priority loop of strict-priority inverse kinematics (Baerlocher & Boulic; paper
/// eq. 6–8, thesis Alg. 3): the linear algebra only, on given Jacobians and desired variations.
///
/// For levels k = 1..p (1 = highest priority), with Δθ_0 given (zero, or the variations imposed
/// on clamped joints) and P_0 = diag(free) (identity without clamping):
///
///   Ĵ_k  = J_k P_{k−1}
///   Δθ_k = Δθ_{k−1} + Ĵ_k^{+λ_k} (Δx_k − J_k Δθ_{k−1})                       (6)
///   P_k  = P_{k−1} − Ĵ_k^+ Ĵ_k                          recursive, O(p)        (8)
///   P_k  = P_0 − (J_k^A P_0)^+ (J_k^A P_0)               full, Siciliano–Slotine (7)
///
/// with J_k^A the k first Jacobians stacked. Ĵ^{+λ} is the damped least-squares inverse
/// Σ σ_i/(σ_i²+λ²) v_i u_iᵀ (paper Annex); the projectors always use the plain pseudo-inverse
/// with an absolute rank threshold on σ. Because Ĵ_k^{+λ} maps into range(P_{k−1}), a level
/// never moves any higher level, whatever its damping (strictness).
///
/// Every pseudo-inverse comes from one thin SVD of Ĵᵀ (n × m, m ≤ n small): Ĵ^+, Ĵ^{+λ} and the
/// row-space projector Ĵ^+Ĵ = U_r U_rᵀ from the same factorisation. The last level, when
/// damped, needs no projector and is solved by Cholesky on its Gram matrix (its rank is then
/// reported as −1). The coordinates Δθ are
/// whatever the Jacobians' columns are (the IK solver uses its own, see solver.hpp).
#include <limits>
#include <vector>

#include "mannequin/math/types.hpp"

namespace mannequin::ik {

using math::MatrixX;
using math::VectorX;

/// How P_k is obtained.
enum class ProjectorUpdate {
  kRecursive,  ///< eq. (8): P_k = P_{k−1} − Ĵ_k^+ Ĵ_k, cost O(p)
  kFull,       ///< eq. (7): recomputed from the augmented Jacobian, cost O(p²) (reference)
};

/// One level of the linearised problem: Δx_k ≈ J_k Δθ.
struct LinearLevel {
  MatrixX J;             ///< (m_k × n)
  VectorX dx;            ///< (m_k) desired variation
  double damping = 0.0;  ///< λ_k ≥ 0 (0: plain pseudo-inverse)
};

struct PriorityOptions {
  ProjectorUpdate update = ProjectorUpdate::kRecursive;
  double rank_tolerance = 1e-9;  ///< absolute threshold on singular values (projectors, λ = 0)
  /// Largest coordinate of one level's contribution Δθ_k − Δθ_{k−1}; a larger contribution is
  /// scaled down (its direction is kept, it stays in range(P_{k−1}), so the higher levels are
  /// untouched and the lower ones compensate what it actually does). ∞ = no limit.
  double max_step = std::numeric_limits<double>::infinity();
};

/// A coordinate held at a given variation from one level on (the clamping loop's joint limits,
/// solver.hpp): the levels above `level` use the coordinate freely; then the row
/// e_iᵀ Δθ = dtheta is solved with strict priority just above `level` (plain pseudo-inverse in
/// the null space of the higher levels) and taken out of the projector for `level` and below.
/// Its contribution counts in column `level` of contributions(). Levels are 0-based; a clamp for
/// every level is P_0 = diag(free) with Δθ_0 instead, so here 1 ≤ level < p.
struct LevelClamp {
  int coordinate = 0;
  int level = 1;
  double dtheta = 0.0;
};

/// Reusable priority loop for n coordinates. Allocates its workspace on first use of each
/// level size; solve() is allocation-free once the sizes have been seen.
class PriorityLoop {
 public:
  explicit PriorityLoop(int n, PriorityOptions options = {});

  /// Runs the loop. \param free optional (n) mask: 1 = coordinate takes part, 0 = clamped
  /// (P_0 = diag(free)); nullptr = all free. \param dtheta0 optional (n) Δθ_0 (the variations
  /// imposed on clamped coordinates); nullptr = 0. \param clamps optional coordinates held from
  /// a lower level on (LevelClamp). \returns Δθ_p (n).
  /// \throws std::invalid_argument on inconsistent sizes, a negative or NaN damping, a
  /// non-finite J or Δx (naming the level), or a clamp out of range.
  const VectorX& solve(const std::vector<LinearLevel>& levels, const VectorX* free = nullptr,
                       const VectorX* dtheta0 = nullptr, const std::vector<LevelClamp>* clamps = nullptr);

  int size() const { return n_; }
  const PriorityOptions& options() const { return options_; }
  void setUpdate(ProjectorUpdate u) { options_.update = u; }

  /// After solve(): Δθ_p, the last projector computed (P_{p−1} when the last level is damped,
  /// else P_p), the rank of each Ĵ_k (−1: not computed).
  const VectorX& dtheta() const { return dtheta_; }
  const MatrixX& projector() const { return P_; }
  const std::vector<int>& ranks() const { return ranks_; }
  /// After solve(): the contribution of each level, column k = Δθ_k − Δθ_{k−1} (n × p), so that
  /// Δθ_p = Δθ_0 + Σ_k column k (a LevelClamp's contribution is in its level's column). Scaling
  /// the columns of the levels below some level i keeps every level ≤ i unchanged to first order
  /// (the convergence loop's backtracking uses this).
  const MatrixX& contributions() const { return C_; }

 private:
  void fullProjector(int rows);  ///< (7) from the first `rows` rows of JA_

  int n_;
  PriorityOptions options_;
  VectorX dtheta_;
  MatrixX P_, P0_, Jhat_, JA_, JAhat_, U_, tmp_, E_;
  VectorX r_, sigma_, w_, rE_;
  std::vector<int> ranks_;
  MatrixX C_;
};

/// The damped least-squares inverse J^{+λ} and, from the same SVD, the plain pseudo-inverse
/// (σ ≤ rank_tolerance dropped). Reference implementations for tests.
MatrixX dampedInverse(const MatrixX& J, double lambda, double rank_tolerance = 1e-9);

}  // namespace mannequin::ik
