#include "mannequin/lcp/qp.hpp"

namespace mannequin::lcp {

const char* qpStatusName(QpStatus status) {
  switch (status) {
    case QpStatus::Solved: return "solved";
    case QpStatus::Infeasible: return "infeasible";
    case QpStatus::OverConstrained: return "over_constrained";
    case QpStatus::RankDeficient: return "rank_deficient";
    case QpStatus::NotConvex: return "not_convex";
    case QpStatus::Invalid: return "invalid";
    case QpStatus::LcpFailure: return "lcp_failure";
  }
  return "invalid";
}

QpResult solveQpAsLcp(const QpProblem& qp, const LemkeOptions& options) {
  QpResult res;
  const Index m = qp.A.cols(), p = qp.A.rows(), ne = qp.C.rows(), ni = qp.E.rows();
  // sizes and finiteness
  if (qp.b.size() != p || qp.Q.rows() != p || qp.Q.cols() != p || (ne > 0 && qp.C.cols() != m) ||
      qp.d.size() != ne || (ni > 0 && qp.E.cols() != m) || qp.f.size() != ni) {
    res.message = "size mismatch between A, b, Q, C, d, E, f";
    return res;
  }
  if (!qp.A.allFinite() || !qp.b.allFinite() || !qp.Q.allFinite() || !qp.C.allFinite() ||
      !qp.d.allFinite() || !qp.E.allFinite() || !qp.f.allFinite()) {
    res.message = "NaN or Inf in the QP data";
    return res;
  }
  // equality conditions of (2): C ∈ G(ne, m) with ne ≤ m and full rank
  if (ne > m) {
    res.status = QpStatus::OverConstrained;
    res.message = "over-constrained: more equality rows than unknowns (C must have ne <= m)";
    return res;
  }
  if (ne > 0) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(qp.C);
    qr.setThreshold(1e-12);
    if (qr.rank() < ne) {
      res.status = QpStatus::RankDeficient;
      res.message = "C is rank deficient: C Q_A^-1 C^T is singular (thesis eq 8)";
      return res;
    }
  }
  // Q_A = AᵀQA must be positive definite (6)
  const Eigen::MatrixXd QA = qp.A.transpose() * qp.Q * qp.A;
  Eigen::LLT<Eigen::MatrixXd> llt(QA);
  if (llt.info() != Eigen::Success || (qp.Q - qp.Q.transpose()).cwiseAbs().maxCoeff() >
                                          1e-12 * (1.0 + qp.Q.cwiseAbs().maxCoeff())) {
    res.status = QpStatus::NotConvex;
    res.message = "A^T Q A is not positive definite (ker A != {0} or Q not SPD)";
    return res;
  }
  const Eigen::MatrixXd QAinv = llt.solve(Eigen::MatrixXd::Identity(m, m));
  const Eigen::VectorXd g = QAinv * (qp.A.transpose() * (qp.Q * qp.b));  // Q_A⁻¹AᵀQb
  // Π and K = Q_A⁻¹Cᵀ(CQ_A⁻¹Cᵀ)⁻¹ (10)
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(m, ne);
  Eigen::MatrixXd Pi = Eigen::MatrixXd::Identity(m, m);
  Eigen::MatrixXd S;
  Eigen::LLT<Eigen::MatrixXd> sllt;
  if (ne > 0) {
    S = qp.C * QAinv * qp.C.transpose();
    sllt.compute(S);
    if (sllt.info() != Eigen::Success) {
      res.status = QpStatus::RankDeficient;
      res.message = "C Q_A^-1 C^T is not invertible";
      return res;
    }
    K = QAinv * qp.C.transpose() * sllt.solve(Eigen::MatrixXd::Identity(ne, ne));
    Pi -= K * qp.C;
  }
  const Eigen::MatrixXd P = Pi * QAinv;  // ΠQ_A⁻¹, symmetric PSD
  const Eigen::VectorXd X0 = -Pi * g + K * qp.d;  // X for μ = 0 (14)
  // LCP (16) on μ
  LcpProblem lcp;
  lcp.M = qp.E * P * qp.E.transpose();
  lcp.M = 0.5 * (lcp.M + lcp.M.transpose());
  lcp.q = qp.f - qp.E * X0;
  LemkeWorkspace ws;
  res.lcp = solveLemke(lcp, ws, options);
  if (res.lcp.status == LcpStatus::NoSolution) {
    res.status = QpStatus::Infeasible;
    res.message = "Lemke ray termination: the constraints are infeasible";
    return res;
  }
  if (res.lcp.status != LcpStatus::Solved) {
    res.status = res.lcp.status == LcpStatus::Invalid ? QpStatus::Invalid : QpStatus::LcpFailure;
    res.message = res.lcp.message;
    return res;
  }
  // X (14) and λ (8)
  res.mu = res.lcp.z;
  res.X = X0 - P * (qp.E.transpose() * res.mu);
  if (ne > 0) {
    res.lambda = -sllt.solve(qp.C * res.X + qp.C * (QAinv * (qp.E.transpose() * res.mu)) + qp.C * g);
  } else {
    res.lambda.resize(0);
  }
  if (!res.X.allFinite() || !res.lambda.allFinite()) {
    res.status = QpStatus::LcpFailure;
    res.message = "non-finite solution";
    return res;
  }
  res.status = QpStatus::Solved;
  res.message = "solved";
  return res;
}

}  // namespace mannequin::lcp
