#pragma once
/// \file solver.hpp
/// \brief One LCP for every row of a step (thesis Alg. 4, eq. 3.7), over one or more systems.
///
/// Stage 2 of a step, after every system's free motion:
/// 1. each producer (RowProducer) appends its rows at q_k to the RowSet;
/// 2. the LCP 0 ≤ w = M z + q ⊥ z ≥ 0 is assembled: for the force rows R (unilateral rows, both halves
///    of the bilateral ones, and the friction edges), A = Σ_s R_s b_s⁻¹ R_sᵀ (the Delassus matrix),
///      normal/limit row r:  w_r = A_r z_R + R_r q̇_free + max(d_r/δt, −v_rec)   ⊥ λ_r ≥ 0
///      friction edge k of r: w_rk = A_rk z_R + R_rk q̇_free + γ_r                ⊥ β_rk ≥ 0
///      cone of r:           w_γr = μ_r λ_r − Σ_k β_rk                          ⊥ γ_r ≥ 0
///    (a bilateral row e is two rows ±e with distance ±d);
/// 3. solved by Lemke (libs/lcp), warm-started from the previous answer's basis (SolverOptions::warm_start);
///    if Lemke fails (ray, pivot limit, residual check), the
///    frictionless problem (normals and limits only, M = A Aᵀ PSD) is solved by the structured solver,
///    then by PGS; the report says which and is flagged. If every solver fails, no force is applied
///    (the step goes on unconstrained) — never a NaN;
/// 4. Γ_s = Σ_r R_{r,s}ᵀ z_r goes to each system (q̇_s = q̇_free,s + b_s⁻¹ Γ_s), and every row's λ (and
///    friction magnitude) is written back into the RowSet for diagnostics;
/// 5. refinement (Lemke answers only, at most `refine_rounds` times): with the velocities q̇_s of the
///    answer, each producer may replace the first-order prediction d + δt J q̇ of its rows by the
///    distance it really reaches, d(q_k ⊕ δt q̇) — RowProducer::refine() sets RowInfo::correction to
///    d(q_k ⊕ δt q̇) − d − δt J q̇ (the curvature of the distance along the step) — and the LCP is
///    solved again with the same matrix (a fixed point: the correction is O(δt²|q̇|²) and its change
///    between rounds O(δt) smaller). Used by the ball joints' swing/twist rows, whose distances are
///    curved (joint_limits.hpp); contacts and revolute limits are linear over a step and do not refine.
///    If a re-solve fails, the previous answer is kept.
/// Preallocated for capacities given at construction; solve() allocates nothing once the LCP
/// workspaces have held a problem of the largest size seen (tests/constraints/solver_alloc_test.cpp).
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "mannequin/constraints/rows.hpp"
#include "mannequin/constraints/system.hpp"
#include "mannequin/lcp/lemke.hpp"
#include "mannequin/lcp/pgs.hpp"
#include "mannequin/lcp/structured.hpp"

namespace mannequin::constraints {

/// Appends rows for a step. Producers keep a pointer to what they read (a model's Data, the contact
/// set ...) and are called in the order they were added.
class RowProducer {
 public:
  virtual ~RowProducer() = default;
  virtual const char* name() const = 0;
  /// Appends this step's rows (distance at q_k, Jacobians) to `rows`, with info.producer = `id`.
  /// Must not throw or allocate in the loop.
  virtual void addRows(int id, double dt, RowSet& rows) = 0;
  /// Refinement round (step 5 above): `velocity[s]` is system s's q̇ = q̇_free + b⁻¹Γ of the current
  /// answer (λ written in `rows`). May set RowInfo::correction of its own rows; returns true when a
  /// correction changed enough that the LCP must be solved again. Must not throw or allocate.
  /// Default: nothing (false).
  virtual bool refine(int /*id*/, double /*dt*/, RowSet& /*rows*/, const std::vector<Eigen::VectorXd>& /*velocity*/) {
    return false;
  }
  /// Called after the solve with the rows (λ written); default: nothing.
  virtual void solved(int /*id*/, const RowSet& /*rows*/) {}
};

enum class SolverUsed : std::uint8_t { kNone, kLemke, kStructured, kPgs, kFailed };
const char* solverUsedName(SolverUsed s);

struct SolverOptions {
  int max_rows = 512;           ///< rows of every kind per step
  int max_friction_rows = 256;  ///< rows with a friction cone per step
  int max_edges = 4;            ///< largest friction_edges of a row
  int refine_rounds = 6;        ///< re-solves for the producers' corrections (step 5; 0: none)
  /// Warm start (step 3): each LCP is first tried with the basis of the previous answer — the previous
  /// step's, rows matched by (producer, tag, source, systems), or the previous refinement round's —
  /// and Lemke runs only when that guess fails the final check (lcp::solveLemkeWarm).
  bool warm_start = true;
  lcp::LemkeOptions lemke;
  lcp::StructuredOptions structured;
  lcp::PgsOptions pgs;
};

/// What one solve did (per step diagnostics).
struct SolveReport {
  SolverUsed solver = SolverUsed::kNone;
  lcp::LcpStatus lemke_status = lcp::LcpStatus::Solved;  ///< Lemke's status (when it ran)
  int rows = 0;          ///< rows produced
  int lcp_size = 0;      ///< n of the LCP solved
  int active = 0;        ///< rows with λ > 0
  int pivots = 0;        ///< Lemke pivots (or the fallback's iterations; the last solve when refined)
  int refine_rounds = 0; ///< LCP re-solves for the producers' corrections (step 5)
  int lcp_solves = 0;    ///< Lemke solves (the first and the refinement rounds')
  int warm = 0;          ///< of those, answered by the warm-start guess (0 pivots)
  long dropped = 0;      ///< rows dropped for capacity since construction
  int refused_forces = 0; ///< systems that refused their constraint force this solve (non-finite): skipped
  bool fallback = false; ///< Lemke failed and a fallback answered (or nothing did)
  double produce_s = 0, assemble_s = 0, solve_s = 0;  ///< wall time of each stage (s)
};

class ConstraintSolver {
 public:
  /// `systems`: the systems the rows may act on (pointers kept; they must outlive the solver).
  /// \throws std::invalid_argument on no system, more than 64 systems, a null system or bad options.
  ConstraintSolver(std::vector<ConstrainedSystem*> systems, const SolverOptions& options = {});
  ~ConstraintSolver();

  /// Adds a producer (kept; not owned); returns its id. Not in the loop.
  int addProducer(RowProducer* producer);
  int numProducers() const { return static_cast<int>(producers_.size()); }

  /// Stage 2 for every system (after their free motion, before their integration). Never throws.
  const SolveReport& solve(double dt);

  const RowSet& rows() const { return rows_; }
  const SolveReport& report() const { return report_; }
  long failures() const { return failures_; }     ///< solves where Lemke failed (fallback or none)
  long unsolved() const { return unsolved_; }     ///< solves where every solver failed
  const SolverOptions& options() const { return options_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<ConstrainedSystem*> systems_;
  std::vector<RowProducer*> producers_;
  SolverOptions options_;
  RowSet rows_;
  SolveReport report_;
  long failures_ = 0, unsolved_ = 0;
};

}  // namespace mannequin::constraints
