#pragma once
/// \file variational_balance.hpp
/// \brief Balance of the whole mannequin, variational form (thesis 3.96–3.107, Algorithm 5).
///
/// One step: at q_k, unknowns X = (f^dis, δq) — the edge forces and a configuration change (δq in the
/// model's velocity coordinates: q_{k+1} = integrate(q_k, δq)). The CoM is linearised,
/// x_com(q_{k+1}) ≈ x_com,k + J_com δq (3.96), so the static equilibrium with margins (3.89) becomes
///   G_f f + G_x J_com δq = W' − G_x x_com,k                                      (3.98)
/// and the contacts are preserved (3.99–3.102): each body in contact keeps its desired pose,
///   J(body) δq = δx(body)   with δx = (log(R_d Rᵀ), p_d − p) (LOCAL_WORLD_ALIGNED: angular velocity
///   and origin velocity in world axes; Alg. 5's log(H_d H⁻¹) that brings a drifted contact back);
/// a body with one contact point keeps that point's position only (3 rows, 3.101), a body with two or
/// more keeps its whole pose (6 rows: the points' 3-row sets of one rigid body are linearly dependent,
/// and the QP→LCP needs independent equality rows). Tasks (3.106): [0 I] J(frame) δq = the step towards
/// the frame's target, at most `max_task_step` long. Bounds (3.104–3.105): |δq_j| ≤ max_step (small
/// displacements) and, for revolute coordinates, lower − q ≤ δq ≤ upper − q (ball joints' swing/twist
/// limits are not linear in δq and are left to the simulation's limit rows). Criterion (3.107):
/// ½(‖f − f_d‖²_{w_f} + α‖(I − NNᵀ)Af‖² + ‖δq − δq_d‖²_{w_q}) (δq_d = 0 in 3.107; the internal control of
/// the thesis's 4.1 otherwise), solved as the LCP (3.70) over the edge forces and
/// the bounds (BalanceQp). The margins' bias is removed from f as in (3.92).
///
/// Contact points and targets are world positions; contacts are given on a joint of the model (the
/// point moves with that joint's frame).
#include <string>
#include <vector>

#include "mannequin/balance/balance_qp.hpp"
#include "mannequin/balance/static_balance.hpp"
#include "mannequin/math/se3.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::balance {

/// A point of a mannequin's segment in contact: `joint` carries it, `local_point` in that joint's frame.
/// The normal (direction the environment pushes, world), μ and the desired force as in PointContact.
struct BodyContact {
  int joint = -1;
  math::Vector3 local_point = math::Vector3::Zero();
  math::Vector3 normal = math::Vector3::UnitZ();
  double mu = 0.5;
  math::Vector3 desired_force = math::Vector3::Zero();
};

/// A held body: its joint frame's desired pose (world), e.g. where it was when the contact was made.
struct HeldBody {
  int joint = -1;
  math::SE3 desired;
};

/// A position task on a model frame (3.106): its origin towards `target` (world).
struct PositionTask {
  int frame = -1;
  math::Vector3 target = math::Vector3::Zero();
};

struct VariationalBalanceProblem {
  std::vector<BodyContact> contacts;
  /// The bodies in contact and their desired poses: one entry per joint that carries a contact.
  /// holdCurrentPoses() fills it with the poses at q (Alg. 5's first loop).
  std::vector<HeldBody> held;
  std::vector<PositionTask> tasks;
  math::Vector3 gravity = math::Vector3(0, 0, -9.81);
  math::Vector6 external_wrench = math::Vector6::Zero();  ///< (moment about the origin, force), world
  int edges = 4;
  double force_weight = 1.0;    ///< w_f (1/N²)
  double alpha = 1.0;           ///< tangential forces (3.69)
  double dq_weight = 1e6;       ///< w_q on δq (1/rad², 1/m²): 1 mrad weighs as 1 N of edge force
  double max_step = 0.02;       ///< |δq_j| bound of the small-displacement hypothesis (rad or m)
  double max_task_step = 0.01;  ///< m, the most a task moves its frame in one step
  std::vector<math::Vector3> com_margins;
  std::vector<math::Vector6> force_margins;
  /// The margins' edge reserves from G_f⁺ (the CoM given, as forceMargin) rather than from the whole G⁺
  /// (3.95, the CoM free): then each push D is balanced by non-negative edge forces at the step's own
  /// linearised CoM, where with the thesis's form part of D's moment is taken by a CoM shift
  /// (G⁺)_x D the posture does not make. The sim's balance controller sets it.
  bool margins_at_com = false;
  /// The internal control of the thesis's (4.1) (4.4.1): the criterion's ‖δq‖²_{w_q} becomes
  /// ‖δq − δq_d‖²_{w_q}, δq_d = β (q_d ⊖ q) pulling the posture towards q_d where the equilibrium, the
  /// held bodies and the tasks leave it free. Empty: 0, as (3.107). nv entries (velocity coordinates).
  skeleton::VectorX dq_desired;
};

/// The held poses of every joint carrying a contact, at the configuration of `data` (forward kinematics done).
std::vector<HeldBody> holdCurrentPoses(const std::vector<BodyContact>& contacts, const std::vector<math::SE3>& oMi);

struct VariationalBalanceResult {
  BalanceStatus status = BalanceStatus::kInvalid;
  std::string message;
  skeleton::VectorX dq;                    ///< nv: q_{k+1} = integrate(model, q_k, dq)
  Eigen::VectorXd edge_forces;             ///< after the bias removal (3.92)
  std::vector<math::Vector3> forces;       ///< per contact, world
  math::Vector3 com = math::Vector3::Zero();    ///< x_com,k + J_com δq (the linearised CoM at q_{k+1})
  double equilibrium_residual = 0.0;       ///< ‖G_f f + G_x x_com − W‖∞ with the linearised CoM
  double min_raw_edge_force = 0.0;         ///< the smallest edge force before rounding −10⁻¹² to 0 (N)
  int equality_rows = 0, lcp_size = 0, pivots = 0;
};

class VariationalBalanceSolver {
 public:
  VariationalBalanceSolver(const skeleton::Model& model, const lcp::LemkeOptions& options = {});
  ~VariationalBalanceSolver();
  /// One step of Algorithm 5 at q. Never throws on bad data: kInvalid names what is wrong.
  const VariationalBalanceResult& solve(const VariationalBalanceProblem& problem, const skeleton::VectorX& q);
  const VariationalBalanceResult& result() const { return result_; }
  /// The QP of the last solve (its data; asGenericQp() for comparisons).
  const BalanceQp& qp() const { return qp_; }

 private:
  const skeleton::Model* model_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  BalanceQp qp_;
  VariationalBalanceResult result_;
};

}  // namespace mannequin::balance
