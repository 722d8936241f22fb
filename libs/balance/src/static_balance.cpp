#include "mannequin/balance/static_balance.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "mannequin/math/so3.hpp"

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

namespace {
bool finite3(const math::Vector3& v) { return v.allFinite(); }
std::string vec(const math::Vector3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", v.x(), v.y(), v.z());
  return buf;
}
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
}  // namespace

StaticBalanceSolver::StaticBalanceSolver(const lcp::LemkeOptions& options) : options_(options) {}

bool StaticBalanceSolver::validate(const StaticBalanceProblem& p) {
  auto fail = [&](std::string what) {
    result_.status = BalanceStatus::kInvalid;
    result_.message = "static balance: " + std::move(what);
    return false;
  };
  if (!(p.mass > 0) || !std::isfinite(p.mass)) return fail("mass must be > 0 and finite (got " + num(p.mass) + " kg)");
  if (!finite3(p.gravity) || p.gravity.norm() < 1e-9) return fail("gravity must be finite and non-zero (got " + vec(p.gravity) + ")");
  if (!p.external_wrench.allFinite()) return fail("external_wrench has a NaN or Inf");
  if (!finite3(p.desired_com)) return fail("desired_com has a NaN or Inf");
  if (p.edges < 3 || p.edges > 64) return fail("edges per cone must be in 3..64 (got " + std::to_string(p.edges) + ")");
  if (!(p.force_weight > 0) || !std::isfinite(p.force_weight)) return fail("force_weight must be > 0 and finite");
  if (!(p.com_weight > 0) || !std::isfinite(p.com_weight)) return fail("com_weight must be > 0 and finite");
  if (!(p.alpha >= 0) || !std::isfinite(p.alpha)) return fail("alpha must be >= 0 and finite");
  if (p.contacts.empty()) return fail("no contact: nothing can carry the weight");
  for (std::size_t i = 0; i < p.contacts.size(); ++i) {
    const PointContact& c = p.contacts[i];
    const std::string at = "contact " + std::to_string(i) + ": ";
    if (!finite3(c.point)) return fail(at + "point has a NaN or Inf");
    if (!finite3(c.normal) || c.normal.norm() < 1e-9) return fail(at + "normal must be finite and non-zero (got " + vec(c.normal) + ")");
    if (!(c.mu >= 0) || !std::isfinite(c.mu)) return fail(at + "mu must be >= 0 and finite (got " + num(c.mu) + ")");
    if (!finite3(c.desired_force)) return fail(at + "desired_force has a NaN or Inf");
  }
  for (std::size_t i = 0; i < p.com_margins.size(); ++i)
    if (!finite3(p.com_margins[i])) return fail("com_margins[" + std::to_string(i) + "] has a NaN or Inf");
  for (std::size_t i = 0; i < p.force_margins.size(); ++i)
    if (!p.force_margins[i].allFinite()) return fail("force_margins[" + std::to_string(i) + "] has a NaN or Inf");
  return true;
}

void StaticBalanceSolver::buildEdges(const StaticBalanceProblem& p) {
  const int mc = static_cast<int>(p.contacts.size()), ma = p.edges;
  edges_.resize(3, mc * ma);
  for (int i = 0; i < mc; ++i) {
    const PointContact& c = p.contacts[static_cast<std::size_t>(i)];
    const math::Vector3 n = c.normal.normalized();
    // tangent basis: t1 ⟂ n along the axis least aligned with n, t2 = n × t1
    math::Vector3 ref = std::abs(n.x()) < 0.9 ? math::Vector3::UnitX() : math::Vector3::UnitY();
    const math::Vector3 t1 = (ref - n * n.dot(ref)).normalized();
    const math::Vector3 t2 = n.cross(t1);
    for (int k = 0; k < ma; ++k) {
      const double th = 2.0 * M_PI * k / ma;
      edges_.col(i * ma + k) = (n + c.mu * (std::cos(th) * t1 + std::sin(th) * t2)).normalized();
    }
  }
}

const StaticBalanceResult& StaticBalanceSolver::solve(const StaticBalanceProblem& p) {
  result_.status = BalanceStatus::kInvalid;
  result_.message.clear();
  result_.pivots = 0;
  result_.equilibrium_residual = 0;
  if (!validate(p)) return result_;
  const int mc = static_cast<int>(p.contacts.size()), ma = p.edges, nf = mc * ma, n = nf + 3;
  result_.lcp_size = nf;
  buildEdges(p);

  // G and W (3.59): edge columns [p × a; a], CoM columns [−[m g]×; 0]
  const math::Vector3 mg = p.mass * p.gravity;
  G_.resize(6, n);
  for (int i = 0; i < mc; ++i)
    for (int k = 0; k < ma; ++k) {
      const int j = i * ma + k;
      const math::Vector3 a = edges_.col(j);
      G_.block<3, 1>(0, j) = p.contacts[static_cast<std::size_t>(i)].point.cross(a);
      G_.block<3, 1>(3, j) = a;
    }
  G_.block<3, 3>(0, nf) = -math::hat(mg);
  G_.block<3, 3>(3, nf).setZero();
  W_.resize(6);
  W_.head<3>().setZero();
  W_.tail<3>() = -mg;
  W_ -= p.external_wrench;

  // desired X (3.69): each contact's desired force as least-norm edge forces, the desired CoM
  Xd_.resize(n);
  for (int i = 0; i < mc; ++i) {
    const math::Vector3& fd = p.contacts[static_cast<std::size_t>(i)].desired_force;
    if (fd.isZero(0.0)) {
      Xd_.segment(i * ma, ma).setZero();
    } else {
      const Eigen::MatrixXd A = edges_.middleCols(i * ma, ma);
      Xd_.segment(i * ma, ma) = A.transpose() * (A * A.transpose()).ldlt().solve(fd);
    }
  }
  Xd_.tail<3>() = p.desired_com;

  // Q_A⁻¹ (block diagonal): per contact (w_f I + α a_iᵀ(I − n nᵀ)a_i)⁻¹, CoM (1/w_x) I
  QAinv_f_.resize(nf, ma);
  for (int i = 0; i < mc; ++i) {
    if (p.alpha == 0.0) {
      QAinv_f_.middleRows(i * ma, ma) = Eigen::MatrixXd::Identity(ma, ma) / p.force_weight;
    } else {
      const math::Vector3 nn = p.contacts[static_cast<std::size_t>(i)].normal.normalized();
      const Eigen::MatrixXd T = (math::Matrix3::Identity() - nn * nn.transpose()) * edges_.middleCols(i * ma, ma);
      const Eigen::MatrixXd B = p.force_weight * Eigen::MatrixXd::Identity(ma, ma) + p.alpha * T.transpose() * T;
      QAinv_f_.middleRows(i * ma, ma) = B.llt().solve(Eigen::MatrixXd::Identity(ma, ma));
    }
  }
  const double qx = 1.0 / p.com_weight;
  const auto applyQAinv = [&](const Eigen::VectorXd& r, Eigen::VectorXd& out) {
    out.resize(n);
    for (int i = 0; i < mc; ++i) out.segment(i * ma, ma) = QAinv_f_.middleRows(i * ma, ma) * r.segment(i * ma, ma);
    out.tail<3>() = qx * r.tail<3>();
  };

  // H = Q_A⁻¹Gᵀ (n×6), S = G Q_A⁻¹ Gᵀ (6×6)
  H_.resize(n, 6);
  for (int i = 0; i < mc; ++i)
    H_.middleRows(i * ma, ma) = QAinv_f_.middleRows(i * ma, ma) * G_.middleCols(i * ma, ma).transpose();
  H_.bottomRows<3>() = qx * G_.rightCols<3>().transpose();
  const Eigen::Matrix<double, 6, 6> S = G_ * H_;
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> S_llt(S);
  if (S_llt.info() != Eigen::Success || S_llt.rcond() < 1e-12) {
    result_.status = BalanceStatus::kDegenerate;
    result_.message = "static balance: G Q_A^-1 G^T is singular (G is not of full rank: the " + std::to_string(mc) +
                      " contact(s) and the CoM cannot produce every component of a wrench; thesis 3.3.2.2)";
    return result_;
  }

  // margins (3.72–3.95): ν = G⁺W, ν'_f = min(ν_f, ν'_f_i), W' = W + G_f(ν'_f − ν_f)
  Wm_ = W_;
  nu_f_.setZero(nf);
  nu_prime_f_.setZero(nf);
  if (!p.com_margins.empty() || !p.force_margins.empty()) {
    const Eigen::Matrix<double, 6, 6> S0 = G_ * G_.transpose();
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> S0_llt(S0);
    const Eigen::Matrix<double, 6, 1> s0w = S0_llt.solve(Eigen::Matrix<double, 6, 1>(W_));
    nu_f_ = G_.leftCols(nf).transpose() * s0w;
    nu_prime_f_ = nu_f_;
    if (!p.com_margins.empty()) {
      // Π_fx = −G_fᵀ S0⁻¹ G_x, Π_xx = I − G_xᵀ S0⁻¹ G_x; Π_f T (Δx; 0) = Π_fx Π_xx⁺ Δx
      const Eigen::Matrix<double, 6, 3> s0gx = S0_llt.solve(Eigen::Matrix<double, 6, 3>(G_.rightCols<3>()));
      const Eigen::MatrixXd Pi_fx = -G_.leftCols(nf).transpose() * s0gx;
      const math::Matrix3 Pi_xx = math::Matrix3::Identity() - G_.rightCols<3>().transpose() * s0gx;
      const Eigen::SelfAdjointEigenSolver<math::Matrix3> es(Pi_xx);
      const double smax = std::max(es.eigenvalues().maxCoeff(), 1e-300);
      math::Matrix3 Pinv = math::Matrix3::Zero();
      for (int k = 0; k < 3; ++k)
        if (es.eigenvalues()[k] > 1e-9 * smax)
          Pinv += es.eigenvectors().col(k) * es.eigenvectors().col(k).transpose() / es.eigenvalues()[k];
      for (const math::Vector3& dx : p.com_margins) nu_prime_f_ = nu_prime_f_.cwiseMin(nu_f_ + Pi_fx * (Pinv * dx));
    }
    for (const math::Vector6& D : p.force_margins) {
      const Eigen::Matrix<double, 6, 1> s = S0_llt.solve(Eigen::Matrix<double, 6, 1>(-D));
      nu_prime_f_ = nu_prime_f_.cwiseMin(nu_f_ + G_.leftCols(nf).transpose() * s);
    }
    Wm_ += G_.leftCols(nf) * (nu_prime_f_ - nu_f_);
  }

  // the LCP (3.70): M = (Q_A⁻¹)_ff − H_f S⁻¹ H_fᵀ, q = (Π_G Q_A⁻¹ Q1 X_d + H S⁻¹ W')_f
  Lt_ = S_llt.matrixL().solve(H_.topRows(nf).transpose());  // 6×nf, L⁻¹H_fᵀ
  M_.resize(nf, nf);
  M_.noalias() = -Lt_.transpose() * Lt_;
  for (int i = 0; i < mc; ++i) M_.block(i * ma, i * ma, ma, ma) += QAinv_f_.middleRows(i * ma, ma);
  Eigen::VectorXd r(n);
  r.head(nf) = p.force_weight * Xd_.head(nf);
  r.tail<3>() = p.com_weight * Xd_.tail<3>();
  applyQAinv(r, y_);
  const Eigen::Matrix<double, 6, 1> corr = S_llt.solve(Eigen::Matrix<double, 6, 1>(G_ * y_ - Wm_));
  q_ = (y_ - H_ * corr).head(nf);
  lcp_.reserve(nf);
  const lcp::LcpStatus st = lcp::solveLemke(M_, q_, ws_, options_, lcp_);
  result_.pivots = lcp_.pivots;
  if (st == lcp::LcpStatus::NoSolution) {
    result_.status = BalanceStatus::kInfeasible;
    result_.message = "static balance: no equilibrium exists: the " + std::to_string(mc) +
                      " contact(s) cannot carry the weight and external wrench within their friction cones" +
                      std::string(p.com_margins.empty() && p.force_margins.empty() ? "" : " with the margins asked for");
    return result_;
  }
  if (st != lcp::LcpStatus::Solved) {
    result_.status = BalanceStatus::kLcpFailure;
    result_.message = std::string("static balance: Lemke: ") + lcp::statusName(st) + " (" + lcp_.message + ")";
    return result_;
  }

  // X = Π_G Q_A⁻¹(Q1 X_d + I_fᵀ z) + H S⁻¹ W', then the bias removal (3.92)
  r.head(nf) += lcp_.z.head(nf);
  applyQAinv(r, X_);
  const Eigen::Matrix<double, 6, 1> corr2 = S_llt.solve(Eigen::Matrix<double, 6, 1>(G_ * X_ - Wm_));
  X_ -= H_ * corr2;
  X_.head(nf) -= nu_prime_f_ - nu_f_;
  result_.edge_forces = X_.head(nf).cwiseMax(0.0);  // rounding: −1e-15 is 0
  result_.margin_reserve = nu_f_ - nu_prime_f_;
  result_.com = X_.tail<3>();
  result_.forces.resize(static_cast<std::size_t>(mc));
  for (int i = 0; i < mc; ++i) result_.forces[static_cast<std::size_t>(i)] = edges_.middleCols(i * ma, ma) * result_.edge_forces.segment(i * ma, ma);
  Eigen::VectorXd Xf(n);
  Xf << result_.edge_forces, result_.com;
  result_.equilibrium_residual = (G_ * Xf - W_).cwiseAbs().maxCoeff();
  result_.status = BalanceStatus::kSolved;
  result_.message = "solved";
  return result_;
}

StaticBalanceResult solveStaticBalance(const StaticBalanceProblem& problem, const lcp::LemkeOptions& options) {
  StaticBalanceSolver s(options);
  return s.solve(problem);
}

}  // namespace mannequin::balance
