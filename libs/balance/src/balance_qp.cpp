#include "mannequin/balance/balance_qp.hpp"

#include <algorithm>
#include <cmath>

namespace mannequin::balance {

void BalanceQp::applyQAinv(const Eigen::VectorXd& r, Eigen::VectorXd& out) const {
  const int ma = edges, nf = contacts * edges;
  const Eigen::Index ny = y_weight.size();
  out.resize(nf + ny);
  for (int i = 0; i < contacts; ++i) out.segment(i * ma, ma).noalias() = Binv_.middleRows(i * ma, ma) * r.segment(i * ma, ma);
  out.tail(ny) = r.tail(ny).cwiseQuotient(y_weight);
}

void BalanceQp::Operator::column(Eigen::Index j, Eigen::Ref<Eigen::VectorXd> out) const {
  const BalanceQp& Q = *qp;
  const Eigen::Index nf = static_cast<Eigen::Index>(Q.contacts) * Q.edges;
  out.noalias() = -Q.Lt_.transpose() * Q.Lt_.col(j);
  if (j < nf) {
    const int ma = Q.edges;
    const Eigen::Index i0 = (j / ma) * ma;
    out.segment(i0, ma) += Q.Binv_.block(i0, j % ma, ma, 1);
  } else {
    out[j] += 1.0;
    const int p = Q.partner_[static_cast<std::size_t>(j)];
    if (p >= 0) out[p] -= 1.0;  // the lower and upper rows of one y_j: (+1)(−1)
  }
}

void BalanceQp::Operator::multiply(const lcp::VectorView& z, Eigen::Ref<Eigen::VectorXd> out) const {
  const BalanceQp& Q = *qp;
  const int ma = Q.edges;
  const Eigen::Index nf = static_cast<Eigen::Index>(Q.contacts) * ma;
  out.noalias() = -Q.Lt_.transpose() * (Q.Lt_ * z);
  for (int i = 0; i < Q.contacts; ++i) out.segment(i * ma, ma).noalias() += Q.Binv_.middleRows(i * ma, ma) * z.segment(i * ma, ma);
  for (Eigen::Index a = nf; a < m; ++a) {
    out[a] += z[a];
    const int p = Q.partner_[static_cast<std::size_t>(a)];
    if (p >= 0) out[a] -= z[p];
  }
}

QpOutcome BalanceQp::solve() {
  const int ma = edges, nf = contacts * edges;
  const Eigen::Index ny = y_weight.size(), n = nf + ny, ne = C.rows();
  // Q_A⁻¹ blocks
  Binv_.resize(nf, ma);
  for (int i = 0; i < contacts; ++i) {
    const Eigen::LLT<Eigen::MatrixXd> llt(B.middleRows(i * ma, ma));
    Binv_.middleRows(i * ma, ma) = llt.solve(Eigen::MatrixXd::Identity(ma, ma));
  }
  // the equality rows scaled to unit norm (the same constraints; S better conditioned: the equilibrium
  // rows are in N and N·m, the contact and task rows in m)
  Cs_ = C;
  cs_ = c;
  for (Eigen::Index i = 0; i < ne; ++i) {
    const double norm = Cs_.row(i).norm();
    if (norm > 0) {
      Cs_.row(i) /= norm;
      cs_[i] /= norm;
    }
  }
  // H = Q_A⁻¹Cᵀ (n × ne), S = C H
  H_.resize(n, ne);
  for (int i = 0; i < contacts; ++i)
    H_.middleRows(i * ma, ma).noalias() = Binv_.middleRows(i * ma, ma) * Cs_.middleCols(i * ma, ma).transpose();
  H_.bottomRows(ny) = y_weight.cwiseInverse().asDiagonal() * Cs_.rightCols(ny).transpose();
  S_.noalias() = Cs_ * H_;
  S_llt_.compute(S_);
  if (S_llt_.info() != Eigen::Success || S_llt_.rcond() < 1e-12) return QpOutcome::kDegenerate;
  // unilateral rows: f ≥ 0, y_j ≥ lo_j, −y_j ≥ −hi_j
  lo_idx_.clear();
  hi_idx_.clear();
  for (Eigen::Index j = 0; j < ny; ++j) {
    if (std::isfinite(lower[j])) lo_idx_.push_back(static_cast<int>(j));
    if (std::isfinite(upper[j])) hi_idx_.push_back(static_cast<int>(j));
  }
  const Eigen::Index nl = static_cast<Eigen::Index>(lo_idx_.size()), nh = static_cast<Eigen::Index>(hi_idx_.size());
  const Eigen::Index m = nf + nl + nh;
  // E H (m × ne) and e (m)
  EH_.resize(m, ne);
  e_.resize(m);
  EH_.topRows(nf) = H_.topRows(nf);
  e_.head(nf).setZero();
  for (Eigen::Index k = 0; k < nl; ++k) {
    EH_.row(nf + k) = H_.row(nf + lo_idx_[static_cast<std::size_t>(k)]);
    e_[nf + k] = lower[lo_idx_[static_cast<std::size_t>(k)]];
  }
  for (Eigen::Index k = 0; k < nh; ++k) {
    EH_.row(nf + nl + k) = -H_.row(nf + hi_idx_[static_cast<std::size_t>(k)]);
    e_[nf + nl + k] = -upper[hi_idx_[static_cast<std::size_t>(k)]];
  }
  // the bound rows scaled by √w_j (D M D, D q; z = D z'): their entries are 1/w_j otherwise, far below the
  // force rows' (w_q = 10⁶ against w_f = 1), which Lemke's pivot tolerances would take for noise
  scale_.setOnes(m);
  for (Eigen::Index k = 0; k < nl; ++k) scale_[nf + k] = std::sqrt(y_weight[lo_idx_[static_cast<std::size_t>(k)]]);
  for (Eigen::Index k = 0; k < nh; ++k) scale_[nf + nl + k] = std::sqrt(y_weight[hi_idx_[static_cast<std::size_t>(k)]]);
  // M = D(E Q_A⁻¹ Eᵀ − (EH) S⁻¹ (EH)ᵀ)D, never formed: Lts = L⁻¹(EH)ᵀD (ne × m, S = LLᵀ), and
  // D E Q_A⁻¹ Eᵀ D is block diagonal on the forces (B_i⁻¹) and ±1 between the two bound rows of one y_j
  Lt_ = S_llt_.matrixL().solve(EH_.transpose());
  Lt_ *= scale_.asDiagonal();
  partner_.assign(static_cast<std::size_t>(m), -1);
  for (Eigen::Index a = 0; a < nl; ++a)
    for (Eigen::Index b = 0; b < nh; ++b)
      if (lo_idx_[static_cast<std::size_t>(a)] == hi_idx_[static_cast<std::size_t>(b)]) {
        partner_[static_cast<std::size_t>(nf + a)] = static_cast<int>(nf + nl + b);
        partner_[static_cast<std::size_t>(nf + nl + b)] = static_cast<int>(nf + a);
      }
  // q = E(Π_G Q_A⁻¹ r + H S⁻¹ c) − e, r = (f_pull, w ∘ y_d)
  r_.resize(n);
  r_.head(nf) = f_pull;
  r_.tail(ny) = y_weight.cwiseProduct(y_desired);
  applyQAinv(r_, u_);
  u_ -= H_ * S_llt_.solve(Cs_ * u_ - cs_);  // Π_G Q_A⁻¹ r + H S⁻¹ c
  q_.resize(m);
  q_.head(nf) = u_.head(nf);
  for (Eigen::Index k = 0; k < nl; ++k) q_[nf + k] = u_[nf + lo_idx_[static_cast<std::size_t>(k)]];
  for (Eigen::Index k = 0; k < nh; ++k) q_[nf + nl + k] = -u_[nf + hi_idx_[static_cast<std::size_t>(k)]];
  q_ -= e_;
  q_ = scale_.cwiseProduct(q_);
  op_.qp = this;
  op_.m = m;
  double diag_max = 0;
  for (Eigen::Index j = 0; j < m; ++j) {
    const double ej = j < nf ? Binv_(j, j % ma) : 1.0;
    diag_max = std::max(diag_max, ej - Lt_.col(j).squaredNorm());
  }
  op_.max_abs = diag_max;  // M is PSD: |M_ij| ≤ √(M_ii M_jj) ≤ max_i M_ii
  lcp_.reserve(m);
  ws_.reserve(m);
  const lcp::LcpStatus st = lcp::solveLemke(op_, q_, ws_, options_, lcp_);
  lcp_.z.head(m) = scale_.cwiseProduct(lcp_.z.head(m));
  if (st == lcp::LcpStatus::NoSolution) return QpOutcome::kInfeasible;
  if (st != lcp::LcpStatus::Solved) return QpOutcome::kLcpFailure;
  // X = Π_G Q_A⁻¹(r + Eᵀz) + H S⁻¹ c
  for (Eigen::Index k = 0; k < nf; ++k) r_[k] += lcp_.z[k];
  for (Eigen::Index k = 0; k < nl; ++k) r_[nf + lo_idx_[static_cast<std::size_t>(k)]] += lcp_.z[nf + k];
  for (Eigen::Index k = 0; k < nh; ++k) r_[nf + hi_idx_[static_cast<std::size_t>(k)]] -= lcp_.z[nf + nl + k];
  applyQAinv(r_, X_);
  X_ -= H_ * S_llt_.solve(Cs_ * X_ - cs_);
  return QpOutcome::kSolved;
}

lcp::QpProblem BalanceQp::asGenericQp() const {
  const int ma = edges, nf = contacts * edges;
  const Eigen::Index ny = y_weight.size(), n = nf + ny;
  lcp::QpProblem g;
  Eigen::MatrixXd QA = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < contacts; ++i) QA.block(i * ma, i * ma, ma, ma) = B.middleRows(i * ma, ma);
  QA.bottomRightCorner(ny, ny) = y_weight.asDiagonal();
  Eigen::VectorXd r(n);
  r << f_pull, y_weight.cwiseProduct(y_desired);
  g.A = Eigen::MatrixXd::Identity(n, n);
  g.b = -QA.ldlt().solve(r);
  g.Q = QA;
  g.C = C;
  g.d = c;
  Eigen::Index rows = nf;
  for (Eigen::Index j = 0; j < ny; ++j) rows += (std::isfinite(lower[j]) ? 1 : 0) + (std::isfinite(upper[j]) ? 1 : 0);
  g.E = Eigen::MatrixXd::Zero(rows, n);
  g.f = Eigen::VectorXd::Zero(rows);
  for (Eigen::Index k = 0; k < nf; ++k) g.E(k, k) = -1;  // −f ≤ 0
  Eigen::Index row = nf;
  for (Eigen::Index j = 0; j < ny; ++j) {
    if (std::isfinite(lower[j])) {
      g.E(row, nf + j) = -1;
      g.f[row++] = -lower[j];
    }
    if (std::isfinite(upper[j])) {
      g.E(row, nf + j) = 1;
      g.f[row++] = upper[j];
    }
  }
  return g;
}

}  // namespace mannequin::balance
