#pragma once
/// \file joint_limits.hpp
/// \brief Joint limits as unilateral constraints in the controller's step (thesis 3.7 and Alg. 4, with
/// constraint rows on the limited coordinates instead of contact normals).
///
/// Stage 2 of a mannequin's step (an ArticulatedSystem, system.hpp; sim::MannequinSystem for the controller),
/// between its free motion and its integration. With q_k, the free velocity q̇_f (qdotFree), b the apparent
/// friction (its Cholesky factor) and δt the step:
/// - candidate j: a coordinate with a finite limit that is within `activation` of it, or would pass it,
///   at q_k + δt q̇_f (revolute: the angle; ball: one component of the rotation vector);
/// - its row J_j (1 × nv) is the rate of that coordinate: s_j e_jᵀ for a revolute coordinate, s_j times a
///   row of Jr(q)⁻¹ on the ball's three velocity columns (q̇ = Jr(q)⁻¹ω, ω the body angular velocity);
///   s_j = +1 for a lower limit, −1 for an upper one, so that J_j q̇ > 0 moves away from the limit;
/// - distance d_j = s_j (q_j − limit_j) (< 0 past the limit);
/// - the LCP 0 ≤ w = J_c b⁻¹ J_cᵀ λ + J_c q̇_f + max(d/δt, −v_rec) ⊥ λ ≥ 0 (Lemke, libs/lcp): w_j ≥ 0 keeps
///   q_{k+1} on the right side of the limit to first order (a coordinate already past it comes back at
///   `recovery_speed` at most, never with a jump), λ_j ≥ 0 (N·m) only pushes, and only at an active limit;
/// - Γ_c = J_cᵀ λ goes to the system's applyConstraintForce (q̇ = q̇_f + b⁻¹Γ_c).
/// J_c b⁻¹ J_cᵀ is symmetric positive definite for distinct coordinates, so the LCP has one solution.
/// The forces at the candidates move the other coordinates too (b⁻¹ couples them): a coordinate that
/// q̇ = q̇_f + b⁻¹J_cᵀλ would carry past its limit joins the candidates and the LCP is solved again
/// (at most `max_rounds` more times).
/// Allocates nothing when no limit is near; with candidates, only when their number changes from the
/// previous step (the LCP's matrices and Lemke's workspace are resized).
#include <utility>
#include <vector>

#include "mannequin/constraints/rows.hpp"
#include "mannequin/constraints/solver.hpp"
#include "mannequin/constraints/swing_twist.hpp"
#include "mannequin/lcp/lemke.hpp"

namespace mannequin::constraints {

struct JointLimitOptions {
  double activation = 0.05;     ///< rad: candidates are this close to a limit at q_k + δt q̇_f
  double recovery_speed = 1.0;  ///< rad/s: how fast a coordinate past its limit is brought back
  int max_rounds = 4;           ///< extra LCP solves when the forces push another coordinate past its limit
};

/// A limit in the LCP at the last step.
struct LimitRow {
  int coordinate = -1;    ///< index in q (swing/twist: the ball's first coordinate)
  bool upper = false;     ///< upper limit (twist: upper bound; swing: false)
  double distance = 0.0;  ///< d_j at q_k (rad; < 0 past the limit)
  double lambda = 0.0;    ///< generalised force along the row (N·m, ≥ 0)
  RowSource source = RowSource::kJointLimit;  ///< kJointLimit, kSwing or kTwist
  int row = -1;           ///< index in the RowSet of the step (−1: dropped for capacity)
};

/// Joint limits as rows of the shared constraint solver (solver.hpp), for one mannequin (system
/// `system` of the ConstraintSolver, the ArticulatedSystem `mannequin`). At q_k, for every limit:
/// - revolute coordinate k (thesis 3.16–3.17): d = q_k − lower (J = e_kᵀ) and upper − q_k (J = −e_kᵀ);
/// - ball joint with swing/twist limits (Joint::ball_limit, Annex D.2, swing_twist.hpp): one swing
///   row d_s (ellipse, rad) and two twist rows θ_t − lower, upper − θ_t, on the ball's 3 velocity
///   columns (ω, body); past kSwingSingular only the radial swing row (the twist is undefined at π);
/// - ball joint without them: the boxes on its rotation-vector components, J = ±row of Jr(q)⁻¹;
/// a row is added (unilateral, source kJointLimit / kSwing / kTwist, recovery_speed from the
/// options) when min(d, d + δt J q̇_free) < activation; a ball's swing and twist rows come together
/// (when one is a candidate, all three are added: the twist and the swing direction turn fast at
/// large swing, so a row far from its limit at q̇_free may still bind after the solve). The
/// solver's LCP keeps d + δt J q̇ ≥ 0: the limit holds to first order in δt at the next step. The
/// swing/twist distances are curved along a step (the ellipse, and s, θ_t nonlinear in R; sliding
/// along the cone at |ω| leaves O(δt²|ω|²/ρ) outside), so refine() gives the solver the rows'
/// linearisation error at the answer's velocity, c = d(R_k exp(δt ω)) − d − δt J ω (R_k exp(δt ω)
/// is how the controller integrates a ball), and the LCP is solved again until c settles (within
/// 1e-9 rad): the limits then hold at q_{k+1} itself, not only to first order. Revolute limits are
/// linear over a step. refine() also appends late rows: limits without a row that the answer carries
/// past (the forces at the other rows move them too), with their correction; the solver assembles
/// again. No allocation in addRows()/refine()/solved().
class JointLimitRows final : public RowProducer {
 public:
  /// \throws std::invalid_argument on non-finite or negative options or system < 0.
  JointLimitRows(const ArticulatedSystem& mannequin, int system, JointLimitOptions options = {});

  const char* name() const override { return "joint_limits"; }
  void addRows(int id, double dt, RowSet& rows) override;
  bool refine(int id, double dt, RowSet& rows, const std::vector<Eigen::VectorXd>& velocity) override;
  void solved(int id, const RowSet& rows) override;

  /// Rows of the last step with their λ (after solved()).
  const std::vector<LimitRow>& rows() const { return rows_; }
  /// Rows with λ > 0 at the last step.
  int activeCount() const;
  /// max over every limited coordinate (and swing/twist) of how far q_k is past its limit (rad, ≥ 0),
  /// at the last addRows().
  double worstExcess() const { return worst_excess_; }
  const JointLimitOptions& options() const { return options_; }
  int system() const { return system_; }

 private:
  struct Box {  // a revolute coordinate or a component of a ball without swing/twist limits
    int q = -1, v = -1, component = -1, ball_q = -1;
    double lower = 0, upper = 0;
  };
  struct BallRow {  // a swing/twist row of the step, for refine()
    int row = -1, joint = -1, ball = -1;  // ball: index in balls_
    int kind = 0;  // 0 swing, 1 twist lower, 2 twist upper
    bool singular = false;
    double d = 0, scale = 0;  // d at q_k, κ at q_k
  };
  /// Rate of a row under q̇_free; true when min(d, d + δt rate) < activation.
  bool candidate(double dt, double d, int v, int ncols, const double* jac) const;
  /// Appends the row (no candidacy test); returns its RowSet index (−1: dropped for capacity).
  int add(int id, RowSet& rows, RowSource source, int coordinate, bool upper, double d, int v, int ncols,
          const double* jac, double correction = 0.0);
  /// Appends box bi's lower or upper row at q_k.
  void addBox(int id, RowSet& rows, std::size_t bi, bool upper, double correction);
  /// Appends ball bi's rows at q_k (d: its distances there; correction: 3 values or null).
  void addBall(int id, RowSet& rows, std::size_t bi, const BallLimitDistances& d, const double* correction);
  const ArticulatedSystem* ctl_;
  int system_;
  JointLimitOptions options_;
  std::vector<Box> boxes_;
  std::vector<int> balls_;  // joints with swing/twist limits
  std::vector<LimitRow> rows_;
  std::vector<BallRow> ball_rows_;
  std::vector<char> box_rows_;       // 2 per box: its lower/upper row is in the step
  std::vector<char> ball_has_rows_;  // per ball: its rows are in the step
  // per ball, from addRows() for refine(): R_k = exp(q_ball) and the distances there (valid when
  // ball_eval_ is set: a ball skipped by the cheap bound has neither)
  std::vector<Eigen::Matrix3d> ball_R_;
  std::vector<BallLimitDistances> ball_d_;
  std::vector<char> ball_eval_;
  // per ball, fixed: the bound behind the cheap skips (see farFromLimits())
  struct BallBound {
    double rho_min = 0;    // rad: smallest ellipse radius over the swing directions (lower bound)
    double slope_min = 0;  // d_s ≥ slope_min (ρ_min − θ_s) for θ_s ≤ ρ_min
    double grad_max = 0;   // |κ dh/ds| ≤ grad_max where θ_s ≤ ρ_min
    double twist_min = 0;  // rad: min(−twist_lower, twist_upper)
  };
  std::vector<BallBound> ball_bound_;
  /// True when every rotation of angle ≤ theta is inside ball bi's cone and twist range with a
  /// linearised distance of at least `margin` after a step of angular speed `speed` (rad/s) over dt.
  bool farFromLimits(std::size_t bi, double theta, double speed, double dt, double margin) const;
  double worst_excess_ = 0.0;
};

/// The joint limits as a stand-alone stage 2 (its own LCP; before the shared ConstraintSolver).
/// Box limits on every coordinate, ball components included (no swing/twist): use JointLimitRows in
/// the ConstraintSolver for those.
class JointLimits {
 public:
  /// \throws std::invalid_argument on non-finite or negative options.
  explicit JointLimits(const skeleton::Model& model, JointLimitOptions options = {});

  /// Stage 2 for `mannequin` (on the same model; e.g. sim::MannequinSystem on a controller): after its free
  /// motion, before integration; dt the step (s). Returns Solved when nothing is near a limit or the LCP was solved (the force is then applied);
  /// on any other status nothing is applied and the status is returned (the step goes on unconstrained).
  lcp::LcpStatus apply(ArticulatedSystem& mannequin, double dt);

  const std::vector<LimitRow>& rows() const { return rows_; }
  /// Rows with λ > 0 at the last apply().
  int activeCount() const;
  long failures() const { return failures_; }
  const JointLimitOptions& options() const { return options_; }

 private:
  struct Coordinate {
    int q = -1, v = -1;     // index in q, first velocity column of its joint
    int component = -1;     // −1: revolute; 0..2: component of a ball's rotation vector
    int ball_q = -1;        // first q index of the ball
    double lower = 0, upper = 0;
  };
  /// Rate of coordinate c under the velocity qdot, and (ball) its row on the joint's 3 velocity columns.
  static double rate(const Coordinate& c, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot);
  static Eigen::RowVector3d ballRow(const Coordinate& c, const Eigen::VectorXd& q);
  std::vector<Coordinate> coordinates_;
  std::vector<std::pair<int, bool>> candidates_;  // (coordinate, upper)
  Eigen::VectorXd qdot_;
  JointLimitOptions options_;
  std::vector<LimitRow> rows_;
  lcp::LemkeWorkspace workspace_;
  lcp::LcpProblem problem_;
  lcp::LcpResult result_;
  Eigen::MatrixXd Jc_, BinvJcT_;
  Eigen::VectorXd gamma_;
  long failures_ = 0;
};

}  // namespace mannequin::constraints
