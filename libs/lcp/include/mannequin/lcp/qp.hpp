#pragma once
/// \file qp.hpp
/// \brief Quadratic program → LCP reformulation of the thesis' Annex A (eqs 2–16).
///
///   min_X ½‖A X + b‖²_Q   s.t.  C X = d,  E X ≤ f
/// with X (m), A p×m (ker A = {0}), Q p×p symmetric positive definite, C ne×m (ne ≤ m, full
/// row rank), E ni×m. With Q_A = AᵀQA, Π = I − Q_A⁻¹Cᵀ(CQ_A⁻¹Cᵀ)⁻¹C the multipliers μ of
/// E X ≤ f solve (16):
///   0 ≤ EΠQ_A⁻¹Eᵀ μ + EΠQ_A⁻¹AᵀQb − EQ_A⁻¹Cᵀ(CQ_A⁻¹Cᵀ)⁻¹d + f ⊥ μ ≥ 0,
/// then X comes from (14) and λ (multipliers of C X = d) from (8). The LCP matrix is
/// symmetric PSD, so Lemke's ray termination proves the constraints infeasible.
#include "mannequin/lcp/lemke.hpp"

namespace mannequin::lcp {

/// Problem data; C/d and E/f may have zero rows.
struct QpProblem {
  Eigen::MatrixXd A;  ///< p×m, full column rank
  Eigen::VectorXd b;  ///< p
  Eigen::MatrixXd Q;  ///< p×p, symmetric positive definite
  Eigen::MatrixXd C;  ///< ne×m, ne ≤ m, full row rank
  Eigen::VectorXd d;  ///< ne
  Eigen::MatrixXd E;  ///< ni×m
  Eigen::VectorXd f;  ///< ni
};

/// Outcome of solveQpAsLcp.
enum class QpStatus {
  Solved,           ///< X, λ, μ satisfy the KKT conditions
  Infeasible,       ///< Lemke ray termination: no X satisfies C X = d, E X ≤ f
  OverConstrained,  ///< more equality rows than unknowns (ne > m)
  RankDeficient,    ///< C is not of full row rank
  NotConvex,        ///< AᵀQA not positive definite (ker A ≠ {0} or Q not SPD)
  Invalid,          ///< size mismatch or NaN/Inf
  LcpFailure,       ///< Lemke hit its pivot limit or a numerical failure
};

/// Short lowercase name of a QP status.
const char* qpStatusName(QpStatus status);

/// Result: X (m), λ (ne) for C X = d, μ (ni) ≥ 0 for E X ≤ f, with the Lagrangian of (3):
/// AᵀQ(AX + b) + Cᵀλ + Eᵀμ = 0.
struct QpResult {
  QpStatus status = QpStatus::Invalid;
  Eigen::VectorXd X;
  Eigen::VectorXd lambda;
  Eigen::VectorXd mu;
  LcpResult lcp;  ///< the inner LCP solve (16)
  const char* message = "";
};

/// Solves the QP through the LCP (16) with Lemke. Allocates (dense factorisations).
QpResult solveQpAsLcp(const QpProblem& qp, const LemkeOptions& options = {});

}  // namespace mannequin::lcp
