#pragma once
/// \file static_balance.hpp
/// \brief Static balance with non-coplanar frictional point contacts (thesis 3.3.2.2, eqs 3.39–3.95).
///
/// Unknowns X = (f^dis, x_com): the force along each edge of each contact's linearised friction cone
/// (m_c contacts × m_a edges) and the centre of mass (world). Everything is in the world frame; the
/// wrench convention is the thesis's (moment about the world origin, then force).
///
/// Static equilibrium (3.52, 3.59):  G X = W, with the column of edge k of contact i
///   G_ik = [p_i × a_ik; a_ik]                (a_ik: unit edge direction, world)
/// and the CoM columns  G_x = [−[m g]×; 0]   (the weight's moment x × m g, linear in x);
///   W = [0; −m g] − W_ext                     (W_ext: the external wrenches, reduced to the origin).
/// With g = (0, 0, −g) this is (3.59)'s [0 −mg 0; mg 0 0; 0 0 0] and (0, 0, 0, 0, 0, mg).
/// Non-sliding contacts (3.62): f^dis ≥ 0. Edges (3.56–3.58): a_ik = (n_i + μ_i (cos θ_k t1 + sin θ_k t2))
/// normalised, θ_k = 2πk/m_a, n_i the contact normal (the direction the environment pushes the mannequin).
///
/// Criterion (3.69):  ½(‖X − (f_d^dis, x_d)‖²_{Q1} + α‖(I − NNᵀ)AX‖²) — close to the desired contact
/// forces and CoM, small tangential forces — with Q1 = diag(force_weight·I, com_weight·I). It is solved as
/// the LCP (3.70)  0 ≤ I_f Π_G Q_A⁻¹ I_fᵀ z + I_f Π_G Q_A⁻¹ Q1 X_d + I_f Q_A⁻¹Gᵀ(G Q_A⁻¹ Gᵀ)⁻¹ W ⊥ z ≥ 0
/// with Lemke (the LCP library): Q_A is block diagonal (an m_a×m_a block per contact, a 3×3 one for the
/// CoM), so Q_A⁻¹ costs little and M is that block diagonal minus a rank-6 term. M is symmetric PSD, so
/// Lemke's ray termination proves that no equilibrium exists (reported kInfeasible, never as solved).
///
/// Stability margins (3.72–3.95). X = ν + Πη with ν = G⁺W and Π = I − G⁺G the projector on ker G.
/// - In CoM position (3.76–3.86): the facets of the polytope Π_f η + ν_f ≥ 0 are moved in by the force
///   change that moves the CoM by Δx_i: ν'_f_i = Π_f T (Δx_i; 0) + ν_f with T from the SVD of Π_x
///   (3.76–3.78). Π_f T (Δx; 0) = Π_fx Π_xx⁺ Δx (Π symmetric idempotent: Π_f Π_xᵀ = Π_fx, Π_x Π_xᵀ = Π_xx),
///   which is what we compute; a test checks it against the SVD form.
/// - In disturbing wrenches (3.93–3.95): ν'_f_i = (G⁺)_f ΔW_i + ν_f, ΔW_i = −D_i for a disturbing
///   external wrench D_i (moment about the origin, force), as W carries −W_ext.
/// - ν'_f = min_i ν'_f_i over the margins and ν_f itself (3.86: the intersection of the polytopes), the
///   problem is solved with W' = G (ν'_f, ν_x) (3.88–3.90), and the bias is removed (3.92):
///   X_final = X − (ν'_f − ν_f, 0). X_final satisfies G X = W, and its edge forces are ≥ ν_f − ν'_f ≥ 0.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "mannequin/balance/balance_qp.hpp"
#include "mannequin/lcp/lemke.hpp"
#include "mannequin/math/types.hpp"

namespace mannequin::balance {

/// A point contact with friction (world frame).
struct PointContact {
  math::Vector3 point = math::Vector3::Zero();
  /// Direction of the normal force the environment exerts on the mannequin (normalised by the solver).
  math::Vector3 normal = math::Vector3::UnitZ();
  double mu = 0.5;  ///< Coulomb friction coefficient (≥ 0)
  /// Desired contact force (N, world), e.g. a hand pushing a lever; zero: none (the criterion keeps
  /// the force small).
  math::Vector3 desired_force = math::Vector3::Zero();
};

/// One static balance problem (3.69) with its optional margins.
struct StaticBalanceProblem {
  std::vector<PointContact> contacts;
  double mass = 0.0;                                    ///< kg (> 0)
  math::Vector3 gravity = math::Vector3(0, 0, -9.81);   ///< m/s², world
  math::Vector6 external_wrench = math::Vector6::Zero();  ///< Σ W_ext: (moment about the origin, force), N·m, N
  math::Vector3 desired_com = math::Vector3::Zero();    ///< x_com_d, world (m)
  int edges = 4;                                        ///< m_a, edges per friction cone (3..64)
  double force_weight = 1.0;  ///< Q1 on the edge forces (1/N²), > 0
  double com_weight = 1e8;    ///< Q1 on the CoM (1/m²), > 0: 1 mm of CoM error weighs as 10 N of edge force
  double alpha = 0.0;         ///< weight of the tangential forces (3.69), ≥ 0
  /// The CoM is not an unknown: it is at desired_com (a given posture), and the equilibrium reads
  /// G_f f = W − G_x x_com; the margins are taken on G_f (ν = G_f⁺W). No CoM-position margins then.
  bool fix_com = false;
  /// CoM-position margins Δx_i (m, world): balanced even with the CoM moved by each of them (3.82).
  std::vector<math::Vector3> com_margins;
  /// Disturbing-wrench margins D_i (moment about the origin, force; world), (3.94–3.95) as the thesis
  /// writes them: the facets move by the f-rows of G⁺ = Gᵀ(GGᵀ)⁻¹ of the whole G. With the CoM free that
  /// pseudo-inverse shares a push's moment between the forces and a CoM shift (G⁺)_x D (the CoM columns
  /// weigh m g per metre): the answer is balanced under D with its CoM moved by that much, not at its
  /// own CoM. With `fix_com` the rows are those of G_f⁺: balanced under D at the given CoM (tipping
  /// guarded; forceMargin uses that form).
  std::vector<math::Vector6> force_margins;
};

enum class BalanceStatus {
  kSolved,      ///< X satisfies G X = W and f^dis ≥ 0 to 10⁻⁶·(1 + ‖W‖∞) (checked on the answer) and is optimal
  kInfeasible,  ///< no static equilibrium exists for these contacts (with these margins): Lemke's ray
  kDegenerate,  ///< G Q_A⁻¹ Gᵀ singular: the contacts and the CoM cannot produce every wrench component
  kInvalid,     ///< bad input (message names it)
  kLcpFailure,  ///< Lemke's pivot limit or a numerical failure
};
const char* balanceStatusName(BalanceStatus status);

struct StaticBalanceResult {
  BalanceStatus status = BalanceStatus::kInvalid;
  std::string message;
  Eigen::VectorXd edge_forces;             ///< f^dis (m_c·m_a), N, ≥ 0 when solved (after the bias removal)
  std::vector<math::Vector3> forces;       ///< per contact, world: Σ_k a_ik f_ik
  math::Vector3 com = math::Vector3::Zero();  ///< x_com (world)
  /// Per edge, the force the margins keep in reserve (ν_f − ν'_f, ≥ 0): the edge forces are at least
  /// this, what the worst margin may take away before the contact slides or lifts; zeros without margins.
  Eigen::VectorXd margin_reserve;
  double equilibrium_residual = 0.0;       ///< ‖G X − W‖∞ (N, N·m)
  double min_raw_edge_force = 0.0;         ///< the smallest edge force before rounding −10⁻¹² to 0 (N)
  int lcp_size = 0;                        ///< m_c·m_a
  int pivots = 0;
};

namespace detail {
struct Equilibrium;
}

/// The solver keeps its matrices between solves (sized by the largest problem seen).
class StaticBalanceSolver {
 public:
  explicit StaticBalanceSolver(const lcp::LemkeOptions& options = {});
  ~StaticBalanceSolver();
  StaticBalanceSolver(StaticBalanceSolver&&) noexcept;
  StaticBalanceSolver& operator=(StaticBalanceSolver&&) noexcept;
  /// Solves one problem; never throws on bad data (kInvalid with a message naming what and where).
  const StaticBalanceResult& solve(const StaticBalanceProblem& problem);
  const StaticBalanceResult& result() const { return result_; }
  /// The QP of the last solve (its data; asGenericQp() for comparisons).
  const BalanceQp& qp() const { return qp_; }

  // -- the matrices of the last solve, for tests and tools --
  /// G (6 × n, n = m_c·m_a + 3) and W (6) of (3.59), with W without the margins' change.
  const Eigen::MatrixXd& equilibriumMatrix() const;
  const Eigen::VectorXd& equilibriumRhs() const;
  /// The unit edge directions a_ik (3 × m_c·m_a, world).
  const Eigen::MatrixXd& edgeDirections() const;

 private:
  BalanceQp qp_;
  std::unique_ptr<detail::Equilibrium> eq_;
  StaticBalanceResult result_;
  Eigen::VectorXd X_, rhs_;
};

/// Stability margin in disturbing forces of a posture (3.93–3.95 used as a measure): the largest F ≤ `max_force`
/// such that `problem` stays solvable with the force margins {F·d_k applied at `point`} for every direction
/// d_k (unit, world) — e.g. ±x, ±y: pushes at the CoM from any horizontal side. Bisection to `tolerance` N.
/// The margin machinery is conservative (one solution keeps a reserve for every push), so the true
/// largest push the contacts can hold is at least this.
struct ForceMarginResult {
  BalanceStatus status = BalanceStatus::kInvalid;  ///< of the problem without margins (kSolved: margin below is valid)
  std::string message;
  double margin_n = 0.0;  ///< N, 0 when the posture itself is not balanced
  int solves = 0;
};
ForceMarginResult forceMargin(StaticBalanceSolver& solver, StaticBalanceProblem problem, const std::vector<math::Vector3>& directions,
                              const math::Vector3& point, double max_force = 2000.0, double tolerance = 1.0);

/// Convenience: one solve with a fresh solver.
StaticBalanceResult solveStaticBalance(const StaticBalanceProblem& problem, const lcp::LemkeOptions& options = {});

}  // namespace mannequin::balance
