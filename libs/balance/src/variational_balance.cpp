#include "mannequin/balance/variational_balance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "equilibrium.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::balance {

std::vector<HeldBody> holdCurrentPoses(const std::vector<BodyContact>& contacts, const std::vector<math::SE3>& oMi) {
  std::vector<HeldBody> held;
  for (const BodyContact& c : contacts) {
    if (c.joint < 0 || c.joint >= static_cast<int>(oMi.size())) continue;
    if (std::none_of(held.begin(), held.end(), [&](const HeldBody& h) { return h.joint == c.joint; }))
      held.push_back({c.joint, oMi[static_cast<std::size_t>(c.joint)]});
  }
  return held;
}

struct VariationalBalanceSolver::Impl {
  explicit Impl(const skeleton::Model& m) : data(m) {}
  skeleton::Data data;
  detail::Equilibrium eq;
  std::vector<PointContact> world;
  std::vector<int> points_on;  // per held body: how many contacts it carries
  skeleton::Matrix6X J6;
  skeleton::Matrix3X J3;
  Eigen::VectorXd Xf;
};

VariationalBalanceSolver::VariationalBalanceSolver(const skeleton::Model& model, const lcp::LemkeOptions& options)
    : model_(&model), impl_(std::make_unique<Impl>(model)), qp_(options) {}
VariationalBalanceSolver::~VariationalBalanceSolver() = default;

const VariationalBalanceResult& VariationalBalanceSolver::solve(const VariationalBalanceProblem& p, const skeleton::VectorX& q) {
  const skeleton::Model& model = *model_;
  Impl& I = *impl_;
  VariationalBalanceResult& r = result_;
  r.status = BalanceStatus::kInvalid;
  r.pivots = 0;
  r.equilibrium_residual = 0;
  const auto fail = [&](const std::string& what) -> const VariationalBalanceResult& {
    r.status = BalanceStatus::kInvalid;
    r.message = "variational balance: " + what;
    return r;
  };
  const int njoints = static_cast<int>(model.joints.size()), nv = model.nv;
  if (q.size() != model.nq || !q.allFinite()) return fail("q must have " + std::to_string(model.nq) + " finite entries");
  if (!(p.dq_weight > 0) || !std::isfinite(p.dq_weight)) return fail("dq_weight must be > 0 and finite");
  if (!(p.max_step > 0) || !std::isfinite(p.max_step)) return fail("max_step must be > 0 and finite");
  if (!(p.max_task_step > 0) || !std::isfinite(p.max_task_step)) return fail("max_task_step must be > 0 and finite");
  if (p.margins_at_com && !p.com_margins.empty())
    return fail("com_margins need margins_at_com off (a CoM-position margin is a CoM shift)");
  if (p.dq_desired.size() != 0 && (p.dq_desired.size() != nv || !p.dq_desired.allFinite()))
    return fail("dq_desired must be empty or have " + std::to_string(nv) + " finite entries");
  for (std::size_t i = 0; i < p.contacts.size(); ++i) {
    const BodyContact& c = p.contacts[i];
    if (c.joint < 0 || c.joint >= njoints) return fail("contact " + std::to_string(i) + ": no joint " + std::to_string(c.joint));
    if (!c.local_point.allFinite()) return fail("contact " + std::to_string(i) + ": local_point has a NaN or Inf");
    if (std::none_of(p.held.begin(), p.held.end(), [&](const HeldBody& h) { return h.joint == c.joint; }))
      return fail("contact " + std::to_string(i) + ": its joint '" + model.joints[static_cast<std::size_t>(c.joint)].name +
                  "' is not held (list it in held, e.g. with holdCurrentPoses)");
  }
  for (std::size_t h = 0; h < p.held.size(); ++h) {
    const HeldBody& b = p.held[h];
    if (b.joint < 0 || b.joint >= njoints) return fail("held " + std::to_string(h) + ": no joint " + std::to_string(b.joint));
    if (!b.desired.R.allFinite() || !b.desired.p.allFinite()) return fail("held " + std::to_string(h) + ": desired pose has a NaN or Inf");
    for (std::size_t k = 0; k < h; ++k)
      if (p.held[k].joint == b.joint) return fail("held " + std::to_string(h) + ": joint listed twice");
  }
  for (std::size_t t = 0; t < p.tasks.size(); ++t) {
    const PositionTask& k = p.tasks[t];
    if (k.frame < 0 || k.frame >= static_cast<int>(model.frames.size())) return fail("task " + std::to_string(t) + ": no frame " + std::to_string(k.frame));
    if (!k.target.allFinite()) return fail("task " + std::to_string(t) + ": target has a NaN or Inf");
  }

  // kinematics at q_k: joint Jacobians, CoM and its Jacobian
  skeleton::computeJointJacobians(model, I.data, q);
  skeleton::jacobianCenterOfMass(model, I.data);
  const math::Vector3 com = I.data.com;
  I.world.resize(p.contacts.size());
  for (std::size_t i = 0; i < p.contacts.size(); ++i) {
    const BodyContact& c = p.contacts[i];
    I.world[i] = {I.data.oMi[static_cast<std::size_t>(c.joint)].act(c.local_point), c.normal, c.mu, c.desired_force};
  }
  const std::string bad = detail::validateCommon(I.world, p.edges, p.force_weight, p.alpha, p.gravity, p.external_wrench,
                                                 p.com_margins, p.force_margins);
  if (!bad.empty()) return fail(bad);

  const int mc = static_cast<int>(p.contacts.size()), ma = p.edges, nf = mc * ma, n = nf + nv;
  detail::Equilibrium& eq = I.eq;
  eq.build(I.world, ma, model.totalMass(), p.gravity, p.external_wrench);  // (3.59) at x_com,k
  eq.margins(p.com_margins, p.force_margins, !p.margins_at_com);              // W' (3.89, 3.95)

  // equality rows (3.102, 3.106)
  I.points_on.assign(p.held.size(), 0);
  for (const BodyContact& c : p.contacts)
    for (std::size_t h = 0; h < p.held.size(); ++h)
      if (p.held[h].joint == c.joint) ++I.points_on[h];
  int ne = 6;
  for (std::size_t h = 0; h < p.held.size(); ++h) ne += I.points_on[h] == 1 ? 3 : 6;
  ne += 3 * static_cast<int>(p.tasks.size());
  r.equality_rows = ne;
  if (ne > n) return fail(std::to_string(ne) + " equality rows for " + std::to_string(n) + " unknowns (thesis 3.107: G'' must not over-constrain)");
  qp_.C.setZero(ne, n);
  qp_.c.resize(ne);
  // equilibrium with the linearised CoM (3.98)
  qp_.C.block(0, 0, 6, nf) = eq.G.leftCols(nf);
  qp_.C.block(0, nf, 6, nv).noalias() = eq.G.rightCols<3>() * I.data.Jcom;
  qp_.c.head<6>() = eq.Wm - eq.G.rightCols<3>() * com;
  int row = 6;
  for (std::size_t h = 0; h < p.held.size(); ++h) {
    const HeldBody& b = p.held[h];
    const math::SE3& now = I.data.oMi[static_cast<std::size_t>(b.joint)];
    if (I.points_on[h] == 1) {
      // one point: its position (3.101), brought back to where the held pose puts it
      const BodyContact* c = nullptr;
      for (const BodyContact& x : p.contacts)
        if (x.joint == b.joint) c = &x;
      skeleton::pointJacobian(model, I.data, b.joint, c->local_point, I.J3);
      qp_.C.block(row, nf, 3, nv) = I.J3;
      qp_.c.segment<3>(row) = b.desired.act(c->local_point) - now.act(c->local_point);
      row += 3;
    } else {
      skeleton::jointJacobian(model, I.data, b.joint, skeleton::ReferenceFrame::kLocalWorldAligned, I.J6);
      qp_.C.block(row, nf, 6, nv) = I.J6;
      qp_.c.segment<3>(row) = math::logSO3(b.desired.R * now.R.transpose());
      qp_.c.segment<3>(row + 3) = b.desired.p - now.p;
      row += 6;
    }
  }
  for (const PositionTask& t : p.tasks) {
    skeleton::frameJacobian(model, I.data, t.frame, skeleton::ReferenceFrame::kLocalWorldAligned, I.J6);
    qp_.C.block(row, nf, 3, nv) = I.J6.bottomRows<3>();
    math::Vector3 step = t.target - I.data.oMf[static_cast<std::size_t>(t.frame)].p;
    if (step.norm() > p.max_task_step) step *= p.max_task_step / step.norm();
    qp_.c.segment<3>(row) = step;
    row += 3;
  }

  // criterion and bounds (3.104–3.107)
  qp_.contacts = mc;
  qp_.edges = ma;
  eq.forceWeights(I.world, ma, p.force_weight, p.alpha, qp_.B);
  qp_.f_pull = p.force_weight * eq.f_desired;
  qp_.y_weight.setConstant(nv, p.dq_weight);
  if (p.dq_desired.size() == nv)
    qp_.y_desired = p.dq_desired;  // the internal control of (4.1): ‖δq − β δq_d‖
  else
    qp_.y_desired.setZero(nv);
  qp_.lower.setConstant(nv, -p.max_step);
  qp_.upper.setConstant(nv, p.max_step);
  for (const skeleton::Joint& j : model.joints) {
    if (j.type != skeleton::JointType::kRevolute) continue;
    const int k = j.idx_v;
    const double lo = model.lower_limit[j.idx_q] - q[j.idx_q], hi = model.upper_limit[j.idx_q] - q[j.idx_q];
    if (std::isfinite(lo)) qp_.lower[k] = std::max(qp_.lower[k], std::min(lo, p.max_step));
    if (std::isfinite(hi)) qp_.upper[k] = std::min(qp_.upper[k], std::max(hi, -p.max_step));
    if (qp_.lower[k] > qp_.upper[k]) qp_.lower[k] = qp_.upper[k];  // beyond a limit: back towards it
  }
  const QpOutcome out = qp_.solve();
  r.lcp_size = qp_.lcpSize();
  r.pivots = qp_.lcp().pivots;
  switch (out) {
    case QpOutcome::kDegenerate:
      r.status = BalanceStatus::kDegenerate;
      r.message = "variational balance: the " + std::to_string(ne) +
                  " equality rows are not independent (contacts, held bodies and tasks conflict)";
      return r;
    case QpOutcome::kInfeasible:
      r.status = BalanceStatus::kInfeasible;
      r.message = "variational balance: no step keeps the equilibrium, the contacts and the tasks within the bounds" +
                  std::string(p.com_margins.empty() && p.force_margins.empty() ? "" : " with the margins asked for");
      return r;
    case QpOutcome::kLcpFailure:
      r.status = BalanceStatus::kLcpFailure;
      r.message = std::string("variational balance: Lemke: ") + lcp::statusName(qp_.lcp().status) + " (" + qp_.lcp().message + ")";
      return r;
    case QpOutcome::kSolved: break;
  }
  const Eigen::VectorXd& X = qp_.X();
  r.dq = X.tail(nv);
  // bias removal (3.92), and the answer's own check: edge forces ≥ 0 and the (linearised) equilibrium
  const double tol = 1e-6 * (1.0 + eq.W.cwiseAbs().maxCoeff());
  r.min_raw_edge_force = (X.head(nf) - (eq.nu_prime_f - eq.nu_f)).minCoeff();
  if (r.min_raw_edge_force < -tol) {
    r.status = BalanceStatus::kLcpFailure;
    r.message = "variational balance: the LCP's answer has a negative edge force (" + detail::num(r.min_raw_edge_force) + " N)";
    return r;
  }
  r.edge_forces = (X.head(nf) - (eq.nu_prime_f - eq.nu_f)).cwiseMax(0.0);
  r.forces.resize(static_cast<std::size_t>(mc));
  for (int i = 0; i < mc; ++i) r.forces[static_cast<std::size_t>(i)] = eq.edges.middleCols(i * ma, ma) * r.edge_forces.segment(i * ma, ma);
  r.com = com + I.data.Jcom * r.dq;
  I.Xf.resize(nf + 3);
  I.Xf << r.edge_forces, r.com;
  r.equilibrium_residual = (eq.G * I.Xf - eq.W).cwiseAbs().maxCoeff();
  if (!(r.equilibrium_residual <= tol)) {
    r.status = BalanceStatus::kLcpFailure;
    r.message = "variational balance: the answer misses the linearised equilibrium by " + detail::num(r.equilibrium_residual);
    return r;
  }
  r.status = BalanceStatus::kSolved;
  r.message = "solved";
  return r;
}

}  // namespace mannequin::balance
