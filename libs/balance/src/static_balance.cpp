#include "mannequin/balance/static_balance.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "equilibrium.hpp"

namespace mannequin::balance {

const char* balanceStatusName(BalanceStatus status) {
  switch (status) {
    case BalanceStatus::kSolved: return "solved";
    case BalanceStatus::kInfeasible: return "infeasible";
    case BalanceStatus::kDegenerate: return "degenerate";
    case BalanceStatus::kInvalid: return "invalid";
    case BalanceStatus::kLcpFailure: return "lcp_failure";
  }
  return "invalid";
}

StaticBalanceSolver::StaticBalanceSolver(const lcp::LemkeOptions& options) : qp_(options), eq_(std::make_unique<detail::Equilibrium>()) {}
StaticBalanceSolver::~StaticBalanceSolver() = default;
StaticBalanceSolver::StaticBalanceSolver(StaticBalanceSolver&&) noexcept = default;
StaticBalanceSolver& StaticBalanceSolver::operator=(StaticBalanceSolver&&) noexcept = default;

const Eigen::MatrixXd& StaticBalanceSolver::equilibriumMatrix() const { return eq_->G; }
const Eigen::VectorXd& StaticBalanceSolver::equilibriumRhs() const { return eq_->W; }
const Eigen::MatrixXd& StaticBalanceSolver::edgeDirections() const { return eq_->edges; }

const StaticBalanceResult& StaticBalanceSolver::solve(const StaticBalanceProblem& p) {
  result_.status = BalanceStatus::kInvalid;
  result_.message.clear();
  result_.pivots = 0;
  result_.equilibrium_residual = 0;
  std::string bad;
  if (!(p.mass > 0) || !std::isfinite(p.mass)) bad = "mass must be > 0 and finite (got " + detail::num(p.mass) + " kg)";
  else if (!p.desired_com.allFinite()) bad = "desired_com has a NaN or Inf";
  else if (!(p.com_weight > 0) || !std::isfinite(p.com_weight)) bad = "com_weight must be > 0 and finite";
  else if (p.fix_com && !p.com_margins.empty()) bad = "com_margins need the CoM free (fix_com is set)";
  else bad = detail::validateCommon(p.contacts, p.edges, p.force_weight, p.alpha, p.gravity, p.external_wrench, p.com_margins,
                                    p.force_margins);
  if (!bad.empty()) {
    result_.message = "static balance: " + bad;
    return result_;
  }
  const int mc = static_cast<int>(p.contacts.size()), ma = p.edges, nf = mc * ma, n = nf + 3;
  result_.lcp_size = nf;
  detail::Equilibrium& eq = *eq_;
  eq.build(p.contacts, ma, p.mass, p.gravity, p.external_wrench);  // (3.59)
  if (p.fix_com) {
    // the CoM given: G_f f = W − G_x x_com
    rhs_ = eq.W - eq.G.rightCols<3>() * p.desired_com;
    eq.margins(p.com_margins, p.force_margins, false, &rhs_);
  } else {
    eq.margins(p.com_margins, p.force_margins);                    // (3.72–3.95)
  }

  // the criterion (3.69) and the LCP (3.70): B_i = w_f I + α a_iᵀ(I − n nᵀ)a_i, the CoM weighted by w_x
  qp_.contacts = mc;
  qp_.edges = ma;
  eq.forceWeights(p.contacts, ma, p.force_weight, p.alpha, qp_.B);
  qp_.f_pull = p.force_weight * eq.f_desired;
  const int ny = p.fix_com ? 0 : 3;
  qp_.y_weight.setConstant(ny, p.com_weight);
  qp_.y_desired = p.desired_com.head(ny);
  qp_.lower.setConstant(ny, -std::numeric_limits<double>::infinity());
  qp_.upper.setConstant(ny, std::numeric_limits<double>::infinity());
  if (p.fix_com) {
    qp_.C = eq.G.leftCols(nf);
    qp_.c = eq.Wm - eq.G.rightCols<3>() * p.desired_com;
  } else {
    qp_.C = eq.G;
    qp_.c = eq.Wm;
  }
  const QpOutcome out = qp_.solve();
  result_.pivots = qp_.lcp().pivots;
  if (out == QpOutcome::kDegenerate) {
    result_.status = BalanceStatus::kDegenerate;
    result_.message = "static balance: G Q_A^-1 G^T is singular (G is not of full rank: the " + std::to_string(mc) +
                      " contact(s) and the CoM cannot produce every component of a wrench; thesis 3.3.2.2)";
    return result_;
  }
  if (out == QpOutcome::kInfeasible) {
    result_.status = BalanceStatus::kInfeasible;
    result_.message = "static balance: no equilibrium exists: the " + std::to_string(mc) +
                      " contact(s) cannot carry the weight and external wrench within their friction cones" +
                      std::string(p.com_margins.empty() && p.force_margins.empty() ? "" : " with the margins asked for");
    return result_;
  }
  if (out != QpOutcome::kSolved) {
    result_.status = BalanceStatus::kLcpFailure;
    result_.message = std::string("static balance: Lemke: ") + lcp::statusName(qp_.lcp().status) + " (" + qp_.lcp().message + ")";
    return result_;
  }
  // the bias removal (3.92)
  X_ = qp_.X();
  X_.head(nf) -= eq.nu_prime_f - eq.nu_f;
  // the answer's own check: edge forces ≥ 0 and G X = W, to a tolerance relative to the weight
  const double tol = 1e-6 * (1.0 + eq.W.cwiseAbs().maxCoeff());
  result_.min_raw_edge_force = X_.head(nf).minCoeff();
  if (result_.min_raw_edge_force < -tol) {
    result_.status = BalanceStatus::kLcpFailure;
    result_.message = "static balance: the LCP's answer has a negative edge force (" + detail::num(result_.min_raw_edge_force) + " N)";
    return result_;
  }
  result_.edge_forces = X_.head(nf).cwiseMax(0.0);  // rounding: −1e-12 is 0
  result_.margin_reserve = eq.nu_f - eq.nu_prime_f;
  result_.com = p.fix_com ? p.desired_com : math::Vector3(X_.tail<3>());
  result_.forces.resize(static_cast<std::size_t>(mc));
  for (int i = 0; i < mc; ++i) result_.forces[static_cast<std::size_t>(i)] = eq.edges.middleCols(i * ma, ma) * result_.edge_forces.segment(i * ma, ma);
  Eigen::VectorXd Xf(n);
  Xf << result_.edge_forces, result_.com;
  result_.equilibrium_residual = (eq.G * Xf - eq.W).cwiseAbs().maxCoeff();
  if (!(result_.equilibrium_residual <= tol)) {
    result_.status = BalanceStatus::kLcpFailure;
    result_.message = "static balance: the answer misses the equilibrium by " + detail::num(result_.equilibrium_residual);
    return result_;
  }
  result_.status = BalanceStatus::kSolved;
  result_.message = "solved";
  return result_;
}

ForceMarginResult forceMargin(StaticBalanceSolver& solver, StaticBalanceProblem problem, const std::vector<math::Vector3>& directions,
                              const math::Vector3& point, double max_force, double tolerance) {
  ForceMarginResult out;
  if (!point.allFinite() || !(max_force > 0) || !std::isfinite(max_force) || !(tolerance > 0)) {
    out.message = "force margin: point must be finite, max_force and tolerance > 0";
    return out;
  }
  for (const math::Vector3& d : directions)
    if (!d.allFinite() || d.norm() < 1e-9) {
      out.message = "force margin: a direction is zero or not finite";
      return out;
    }
  const auto feasible = [&](double F) {
    problem.force_margins.clear();
    for (const math::Vector3& d : directions) {
      const math::Vector3 f = F * d.normalized();
      math::Vector6 D;
      D << point.cross(f), f;
      problem.force_margins.push_back(D);
    }
    ++out.solves;
    return solver.solve(problem).status == BalanceStatus::kSolved;
  };
  problem.force_margins.clear();
  ++out.solves;
  const StaticBalanceResult& base = solver.solve(problem);
  out.status = base.status;
  out.message = base.message;
  if (base.status != BalanceStatus::kSolved) return out;
  if (feasible(max_force)) {
    out.margin_n = max_force;
    return out;
  }
  double lo = 0, hi = max_force;  // feasible at lo, not at hi
  while (hi - lo > tolerance) {
    const double mid = 0.5 * (lo + hi);
    (feasible(mid) ? lo : hi) = mid;
  }
  out.margin_n = lo;
  return out;
}

StaticBalanceResult solveStaticBalance(const StaticBalanceProblem& problem, const lcp::LemkeOptions& options) {
  StaticBalanceSolver s(options);
  return s.solve(problem);
}

}  // namespace mannequin::balance
