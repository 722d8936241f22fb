#pragma once
/// \file rows.hpp
/// \brief The row-based constraint layer (thesis 3.1.2, Alg. 4, eq. 3.7): every unilateral (and
/// bilateral) constraint of a step is one ROW acting on the velocities of one or two SYSTEMS.
///
/// A system is anything with first-order dynamics b q̇ = Γ (2.4): a mannequin's control::Controller
/// (nv ≈ 40) or a rigid object (nv = 6, or 1 on a hinge). At step k, after each system's free motion
/// q̇_free = b⁻¹Γ, a row r is
///   d̂_r(q_{k+1}) ≈ d_r(q_k) + δt Σ_s J_{r,s} q̇_s,   q̇_s = q̇_free,s + b_s⁻¹ Σ_r' J_{r',s}ᵀ λ_r'
/// with J_{r,s} (1 × nv_s) the rate of the constraint's distance under system s's velocity, d_r the
/// distance at q_k (m or rad; < 0: violated) and λ_r its force (N or N·m). The solver (solver.hpp)
/// stacks every row in one LCP and hands Γ_s = Σ_r J_{r,s}ᵀ λ_r back to each system.
///
/// Row kinds:
/// - kUnilateral: 0 ≤ d̂/δt ⊥ λ ≥ 0 (contact normals, joint limits, swing/twist, balance);
/// - kBilateral: d̂ = 0, λ free (grasps, guides on objects): split by the solver into two unilateral rows;
/// - friction: a unilateral row with friction_edges > 0 and mu > 0 gets a linearised Coulomb cone
///   of `friction_edges` directions t_k = cos(2πk/m) t1 + sin(2πk/m) t2 (t1, t2 ⟂ the normal, given
///   by the producer as tangent Jacobians), in the same LCP (Stewart–Trinkle form: edge forces
///   β_k ≥ 0, a sliding speed γ ≥ 0, μλ − Σβ_k ≥ 0).
///
/// Storage is preallocated by capacity (rows, systems, velocity sizes) at construction: producers
/// write into it every step and nothing is allocated. A producer that would exceed the capacity gets
/// false from add() and the row is dropped (counted in RowSet::dropped()).
#include <cstdint>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

namespace mannequin::constraints {

enum class RowKind : std::uint8_t { kUnilateral, kBilateral };

/// What produced a row (diagnostics, sim.world).
enum class RowSource : std::uint8_t { kJointLimit, kSwing, kTwist, kContact, kBalance, kGrasp, kHinge, kGuide, kOther };
const char* rowSourceName(RowSource s);

/// One row's data besides its Jacobians.
struct RowInfo {
  RowKind kind = RowKind::kUnilateral;
  RowSource source = RowSource::kOther;
  int producer = -1;        ///< index of the producer in the solver
  int tag = -1;             ///< the producer's own index (contact index, coordinate ...)
  double distance = 0.0;    ///< d(q_k): m or rad, < 0 violated (bilateral: the error, target 0)
  double recovery_speed = 1.0;  ///< |d|/δt is capped at this (m/s or rad/s) when d < 0: no jump back
  /// Linearisation error of the distance over the step (m or rad), set by a producer's refine():
  /// the LCP keeps max(d/δt, −v_rec) + correction/δt + J q̇ ≥ 0. 0 unless refined.
  double correction = 0.0;
  double mu = 0.0;          ///< Coulomb coefficient (friction rows only)
  int friction_edges = 0;   ///< m directions of the linearised cone (0: frictionless)
  int system_a = -1, system_b = -1;  ///< systems the row acts on (−1: none, e.g. the static scene)
  double lambda = 0.0;      ///< solved force along the row (N or N·m), written by the solver
  double friction = 0.0;    ///< solved tangential force magnitude |Σ β_k t_k| (N), written by the solver
};

/// Rows of one step for a fixed set of systems. Capacity-based: no allocation after construction.
/// Jacobians are stored row-major: a row (what producers write and the solver reads) is contiguous.
class RowSet {
 public:
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  using RowBlock = Eigen::Block<RowMatrix, 1, Eigen::Dynamic, true>;

  /// `system_nv[s]`: velocity size of system s; `max_rows`: rows of every kind; `max_friction_rows`:
  /// rows that may carry a friction cone; `max_edges`: the largest friction_edges.
  /// \throws std::invalid_argument on 0 or more than 64 systems, a negative nv or bad capacities.
  RowSet(const std::vector<int>& system_nv, int max_rows, int max_friction_rows = 0, int max_edges = 4);

  void clear();
  int size() const { return n_; }
  int capacity() const { return static_cast<int>(info_.size()); }
  int numSystems() const { return static_cast<int>(J_.size()); }
  int systemNv(int s) const { return static_cast<int>(J_[s].cols()); }
  long dropped() const { return dropped_; }

  /// Starts a row; returns its index, or −1 (dropped) when full or when a friction row would exceed
  /// the friction capacity. The row's Jacobians start at zero; fill them with jacobian(row, s).
  int add(const RowInfo& info);
  /// Row r's Jacobian block on system s (1 × nv_s), writable. Marks s as touched by r. For an invalid
  /// r (e.g. −1 from a dropped add()) it is a sink row past the capacity, read by nobody.
  RowBlock jacobian(int r, int s);
  /// Tangent Jacobians of a friction row r on system s: t1 (1 × nv_s) and t2 (1 × nv_s), writable.
  RowBlock tangent(int r, int s, int which);

  const RowInfo& info(int r) const { return info_[r]; }
  RowInfo& info(int r) { return info_[r]; }
  /// ((capacity + 1) × nv_s) Jacobians of system s; rows [0, size()) valid, untouched rows are zero
  /// (the last row is the sink).
  const RowMatrix& jacobians(int s) const { return J_[s]; }
  /// Tangent Jacobians t1 / t2 of system s, indexed by friction slot (frictionSlot(r)).
  const RowMatrix& tangents(int s, int which) const { return which == 0 ? T1_[s] : T2_[s]; }
  /// Friction slot of row r (−1: frictionless).
  int frictionSlot(int r) const { return slot_[r]; }
  int numFrictionRows() const { return nf_; }
  int maxEdges() const { return max_edges_; }
  /// Whether row r touches system s (bit set by jacobian()/tangent()).
  bool touches(int r, int s) const { return (touch_[r] >> s) & 1u; }

 private:
  std::vector<RowInfo> info_;
  std::vector<RowMatrix> J_, T1_, T2_;
  std::vector<int> slot_;
  std::vector<std::uint64_t> touch_;
  int n_ = 0, nf_ = 0, max_edges_ = 4;
  long dropped_ = 0;
};

}  // namespace mannequin::constraints
