#include "mannequin/balance/balance_qp.hpp"

#include <cmath>

namespace mannequin::balance {

void BalanceQp::applyQAinv(const Eigen::VectorXd& r, Eigen::VectorXd& out) const {
  const int ma = edges, nf = contacts * edges;
  const Eigen::Index ny = y_weight.size();
  out.resize(nf + ny);
  for (int i = 0; i < contacts; ++i) out.segment(i * ma, ma).noalias() = Binv_.middleRows(i * ma, ma) * r.segment(i * ma, ma);
  out.tail(ny) = r.tail(ny).cwiseQuotient(y_weight);
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
  // H = Q_A⁻¹Cᵀ (n × ne), S = C H
  H_.resize(n, ne);
  for (int i = 0; i < contacts; ++i)
    H_.middleRows(i * ma, ma).noalias() = Binv_.middleRows(i * ma, ma) * C.middleCols(i * ma, ma).transpose();
  H_.bottomRows(ny) = y_weight.cwiseInverse().asDiagonal() * C.rightCols(ny).transpose();
  S_.noalias() = C * H_;
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
  // M = E Q_A⁻¹ Eᵀ − (EH) S⁻¹ (EH)ᵀ
  Lt_ = S_llt_.matrixL().solve(EH_.transpose());  // ne × m
  M_.resize(m, m);
  M_.noalias() = -Lt_.transpose() * Lt_;
  for (int i = 0; i < contacts; ++i) M_.block(i * ma, i * ma, ma, ma) += Binv_.middleRows(i * ma, ma);
  // y rows of E Q_A⁻¹ Eᵀ: ±1/w_j where the two rows act on the same y_j
  const auto yrow = [&](Eigen::Index k, int& j, double& s) {
    if (k < nl) {
      j = lo_idx_[static_cast<std::size_t>(k)];
      s = 1.0;
    } else {
      j = hi_idx_[static_cast<std::size_t>(k - nl)];
      s = -1.0;
    }
  };
  for (Eigen::Index a = 0; a < nl + nh; ++a)
    for (Eigen::Index b = 0; b < nl + nh; ++b) {
      int ja, jb;
      double sa, sb;
      yrow(a, ja, sa);
      yrow(b, jb, sb);
      if (ja == jb) M_(nf + a, nf + b) += sa * sb / y_weight[ja];
    }
  // q = E(Π_G Q_A⁻¹ r + H S⁻¹ c) − e, r = (f_pull, w ∘ y_d)
  r_.resize(n);
  r_.head(nf) = f_pull;
  r_.tail(ny) = y_weight.cwiseProduct(y_desired);
  applyQAinv(r_, u_);
  u_ -= H_ * S_llt_.solve(C * u_ - c);  // Π_G Q_A⁻¹ r + H S⁻¹ c
  q_.resize(m);
  q_.head(nf) = u_.head(nf);
  for (Eigen::Index k = 0; k < nl; ++k) q_[nf + k] = u_[nf + lo_idx_[static_cast<std::size_t>(k)]];
  for (Eigen::Index k = 0; k < nh; ++k) q_[nf + nl + k] = -u_[nf + hi_idx_[static_cast<std::size_t>(k)]];
  q_ -= e_;
  lcp_.reserve(m);
  const lcp::LcpStatus st = lcp::solveLemke(M_, q_, ws_, options_, lcp_);
  if (st == lcp::LcpStatus::NoSolution) return QpOutcome::kInfeasible;
  if (st != lcp::LcpStatus::Solved) return QpOutcome::kLcpFailure;
  // X = Π_G Q_A⁻¹(r + Eᵀz) + H S⁻¹ c
  for (Eigen::Index k = 0; k < nf; ++k) r_[k] += lcp_.z[k];
  for (Eigen::Index k = 0; k < nl; ++k) r_[nf + lo_idx_[static_cast<std::size_t>(k)]] += lcp_.z[nf + k];
  for (Eigen::Index k = 0; k < nh; ++k) r_[nf + hi_idx_[static_cast<std::size_t>(k)]] -= lcp_.z[nf + nl + k];
  applyQAinv(r_, X_);
  X_ -= H_ * S_llt_.solve(C * X_ - c);
  return QpOutcome::kSolved;
}

}  // namespace mannequin::balance
