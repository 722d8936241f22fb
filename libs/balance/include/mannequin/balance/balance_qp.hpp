#pragma once
/// \file balance_qp.hpp
/// \brief The QP both balance problems reduce to (thesis 3.69 and 3.107), solved as one LCP (3.70).
///
///   min  ½ fᵀBf − f_pullᵀf + ½ Σ_j w_j (y_j − y_d,j)²
///   s.t. C_f f + C_y y = c,   f ≥ 0,   lo ≤ y ≤ hi  (infinite bounds: none)
///
/// f: the edge forces (m_c contacts × m_a edges), B = blockdiag(B_i), B_i the m_a×m_a weight block of
/// contact i (w_f I + α a_iᵀ(I − n nᵀ)a_i: small tangential forces), f_pull = w_f f_d (3.69 pulls f towards
/// the desired f_d by ‖f − f_d‖²_{Q1}; the tangential term penalises f itself); y: the other unknowns (the CoM for the static problem,
/// δq for the variational one) with diagonal weights w. With X = (f, y), Q_A = blockdiag(B_i, diag w)
/// (block diagonal: its inverse costs little), H = Q_A⁻¹Cᵀ, S = C H, the unilateral rows E X ≥ e
/// (f ≥ 0, y − lo ≥ 0, hi − y ≥ 0) give the LCP (Annex A, eq. 16; 3.70)
///   0 ≤ E Π_G Q_A⁻¹ Eᵀ z + E(Π_G Q_A⁻¹ r + H S⁻¹ c) − e  ⊥  z ≥ 0,   Π_G Q_A⁻¹ = Q_A⁻¹ − H S⁻¹ Hᵀ,
/// r = (f_pull, w ∘ y_d), then X = Π_G Q_A⁻¹(r + Eᵀz) + H S⁻¹ c. M is symmetric PSD: Lemke's ray termination
/// proves the constraints infeasible.
#include <vector>

#include <Eigen/Dense>

#include "mannequin/lcp/lemke.hpp"
#include "mannequin/lcp/qp.hpp"

namespace mannequin::balance {

enum class QpOutcome { kSolved, kInfeasible, kDegenerate, kLcpFailure };

class BalanceQp {
 public:
  // -- data, filled by the caller (sizes: nf = m_c·m_a, ny, ne) --
  int contacts = 0, edges = 0;  ///< m_c, m_a
  Eigen::MatrixXd B;            ///< nf × m_a: the blocks B_i stacked (symmetric positive definite)
  Eigen::VectorXd f_pull;       ///< nf: the criterion's linear term on f (w_f f_d)
  Eigen::VectorXd y_weight;     ///< ny, > 0
  Eigen::VectorXd y_desired;    ///< ny
  Eigen::VectorXd lower, upper; ///< ny (−inf / +inf: unbounded)
  Eigen::MatrixXd C;            ///< ne × (nf + ny), full row rank
  Eigen::VectorXd c;            ///< ne

  explicit BalanceQp(const lcp::LemkeOptions& options = {}) : options_(options) {}
  /// Solves; X() holds (f, y) when kSolved.
  QpOutcome solve();
  const Eigen::VectorXd& X() const { return X_; }
  const lcp::LcpResult& lcp() const { return lcp_; }
  int lcpSize() const { return static_cast<int>(op_.m); }
  /// The same QP in the LCP library's generic form (Annex A: min ½‖A X + b‖²_Q, C X = d, E X ≤ f with
  /// A = I, Q = Q_A, b = −Q_A⁻¹r), for comparisons (bench-balance). Allocates.
  lcp::QpProblem asGenericQp() const;

 private:
  /// M of the LCP by its columns and products (Lemke's product form reads only the entering columns).
  struct Operator final : lcp::LcpMatrixOperator {
    const BalanceQp* qp = nullptr;
    Eigen::Index m = 0;
    double max_abs = 0;
    Eigen::Index size() const override { return m; }
    void column(Eigen::Index j, Eigen::Ref<Eigen::VectorXd> out) const override;
    void multiply(const lcp::VectorView& z, Eigen::Ref<Eigen::VectorXd> out) const override;
    double maxAbs() const override { return max_abs; }
  };
  Operator op_;
  std::vector<int> partner_;  // per LCP row: the other bound row of the same y_j (−1: none)
  lcp::LemkeOptions options_;
  lcp::LemkeWorkspace ws_;
  lcp::LcpResult lcp_;
  Eigen::MatrixXd Binv_, Cs_, H_, EH_, Lt_, S_;
  Eigen::LLT<Eigen::MatrixXd> S_llt_;
  Eigen::VectorXd cs_, r_, u_, q_, e_, X_, scale_;
  std::vector<int> lo_idx_, hi_idx_;
  void applyQAinv(const Eigen::VectorXd& r, Eigen::VectorXd& out) const;
};

}  // namespace mannequin::balance
