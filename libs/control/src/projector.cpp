#include "mannequin/control/projector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mannequin/core/check.hpp"

namespace mannequin::control {

const char* toString(ProjectorMethod method) { return method == ProjectorMethod::kSvd ? "svd" : "ldlt"; }

WeightedNullSpace::WeightedNullSpace(int rows, int n, ProjectorMethod method, double rank_tolerance)
    : rows_(rows), n_(n), method_(method), tol_(rank_tolerance) {
  if (rows < 0 || n <= 0) throw std::invalid_argument("WeightedNullSpace: bad size");
  if (!(rank_tolerance > 0) || !(rank_tolerance < 1))
    throw std::invalid_argument("WeightedNullSpace: rank tolerance must be in (0, 1)");
  J_.setZero(rows, n);
  w_inv_.setOnes(n);
  sqrt_w_inv_.setOnes(n);
  Js_.setZero(rows, n);
  G_.setZero(rows, rows);
  y_.setZero(rows);
  z_.setZero(rows);
  t_.setZero(n);
  r_.setZero(rows);
  // factorise once here so that the workspaces are allocated and the decompositions' status is set
  // (Eigen leaves it uninitialised until the first compute, and this object gets copied)
  ldlt_.compute(MatrixX::Identity(rows, rows));
  if (rows > 0 && method == ProjectorMethod::kSvd) svd_ = Eigen::JacobiSVD<MatrixX>(rows, n, Eigen::ComputeThinV);
}

void WeightedNullSpace::compute(const Eigen::Ref<const MatrixX>& J, const VectorX& w_inv) {
  if (J.rows() != rows_ || J.cols() != n_ || w_inv.size() != n_)
    throw std::invalid_argument("WeightedNullSpace::compute: J is " + std::to_string(J.rows()) + "x" +
                                std::to_string(J.cols()) + ", expected " + std::to_string(rows_) + "x" +
                                std::to_string(n_));
  rank_ = 0;
  if (rows_ == 0) return;
  J_ = J;
  w_inv_ = w_inv;
  sqrt_w_inv_ = w_inv.cwiseSqrt();
  // Js = J W^{-1/2}
  Js_.noalias() = J_ * sqrt_w_inv_.asDiagonal();
  if (method_ == ProjectorMethod::kLdlt) {
    // G = J W⁻¹ Jᵀ (lower triangle), pivoted LDLᵀ; rank = pivots above tol · max pivot
    G_.setZero();
    G_.selfadjointView<Eigen::Lower>().rankUpdate(Js_);
    factorGram();
  } else {
    svd_.compute(Js_, Eigen::ComputeThinV);
    const auto& s = svd_.singularValues();
    const double smax = s.size() > 0 ? s(0) : 0.0;
    for (Eigen::Index i = 0; i < s.size(); ++i)
      if (s(i) * s(i) > tol_ * smax * smax && smax > 0) ++rank_;
  }
}

void WeightedNullSpace::factorGram() {
  ldlt_.compute(G_);
  const auto& D = ldlt_.vectorD();
  const double dmax = D.size() > 0 ? D.cwiseAbs().maxCoeff() : 0.0;
  const double cut = tol_ * dmax;
  rank_ = 0;
  for (Eigen::Index i = 0; i < D.size(); ++i)
    if (D(i) > cut && dmax > 0) ++rank_;
}

void WeightedNullSpace::computeWithGram(const Eigen::Ref<const MatrixX>& J, const VectorX& w_inv,
                                        const Eigen::Ref<const MatrixX>& G) {
  if (method_ != ProjectorMethod::kLdlt) {
    compute(J, w_inv);
    return;
  }
  if (J.rows() != rows_ || J.cols() != n_ || w_inv.size() != n_ || G.rows() != rows_ || G.cols() != rows_)
    throw std::invalid_argument("WeightedNullSpace::computeWithGram: J is " + std::to_string(J.rows()) + "x" +
                                std::to_string(J.cols()) + " and G " + std::to_string(G.rows()) + "x" +
                                std::to_string(G.cols()) + ", expected " + std::to_string(rows_) + "x" +
                                std::to_string(n_) + " and " + std::to_string(rows_) + "x" + std::to_string(rows_));
  rank_ = 0;
  if (rows_ == 0) return;
  J_ = J;
  w_inv_ = w_inv;
  G_.triangularView<Eigen::Lower>() = G;
  factorGram();
}

void WeightedNullSpace::projectTorque(const VectorX& g, VectorX& out) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(g.size(), n_, "torque g");
  if (rows_ == 0 || rank_ == 0) {
    if (&out != &g) out = g;
    return;
  }
  if (method_ == ProjectorMethod::kLdlt) {
    // Πᵀg = g − Jᵀ G⁺ J W⁻¹ g, G⁺ = Pᵀ L⁻ᵀ D⁺ L⁻¹ P with the small pivots of D dropped
    t_ = w_inv_.cwiseProduct(g);
    y_.noalias() = J_ * t_;
    z_ = ldlt_.transpositionsP() * y_;
    ldlt_.matrixL().solveInPlace(z_);
    const auto& D = ldlt_.vectorD();
    const double cut = tol_ * D.cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < z_.size(); ++i) z_(i) = D(i) > cut ? z_(i) / D(i) : 0.0;
    ldlt_.matrixU().solveInPlace(z_);
    y_ = ldlt_.transpositionsP().transpose() * z_;
    t_.noalias() = J_.transpose() * y_;
    out = g - t_;
  } else {
    // Πᵀ = I − S⁻¹ V_r V_rᵀ S, S = W^{-1/2}, Js = U Σ Vᵀ
    const auto V = svd_.matrixV().leftCols(rank_);
    t_ = sqrt_w_inv_.cwiseProduct(g);
    auto r = r_.head(rank_);
    r.noalias() = V.transpose() * t_;
    t_.noalias() = V * r;
    out = g - t_.cwiseQuotient(sqrt_w_inv_);
  }
}

MatrixX WeightedNullSpace::matrix() {
  // columns of Πᵀ are Πᵀ e_k; Π is its transpose
  MatrixX PiT(n_, n_);
  VectorX e(n_), col(n_);
  for (int k = 0; k < n_; ++k) {
    e.setZero();
    e(k) = 1.0;
    projectTorque(e, col);
    PiT.col(k) = col;
  }
  return PiT.transpose();
}

namespace {
// The trailing lower block of step k: A_ij −= L_ik A_jk (i ≥ j), column by column: independent axpys
// that the compiler vectorises. Compiled twice: for x86-64's SSE2 and for AVX2 (4 doubles a step), chosen
// at run time; no FMA in either, so both round every product and difference alike (the same bits).
[[gnu::always_inline]] inline void schurUpdate(double* L, Eigen::Index ld, int k, int r, const double* lk, const double* v) {
  for (int j = 0; j < r; ++j) {
    double* cj = L + (k + 1 + j) * ld + (k + 1 + j);
    const double* li = lk + j;
    const double vj = v[j];
    for (int i = 0; i < r - j; ++i) cj[i] -= vj * li[i];
  }
}
void schurUpdatePortable(double* L, Eigen::Index ld, int k, int r, const double* lk, const double* v) {
  schurUpdate(L, ld, k, r, lk, v);
}
#if defined(__x86_64__) && defined(__GNUC__)
[[gnu::target("avx2")]] void schurUpdateAvx2(double* L, Eigen::Index ld, int k, int r, const double* lk, const double* v) {
  schurUpdate(L, ld, k, r, lk, v);
}
bool haveAvx2() { return __builtin_cpu_supports("avx2") != 0; }
#else
void schurUpdateAvx2(double* L, Eigen::Index ld, int k, int r, const double* lk, const double* v) {
  schurUpdate(L, ld, k, r, lk, v);
}
bool haveAvx2() { return false; }
#endif
}  // namespace

PriorityGramFactor::PriorityGramFactor(int rows, int n, double rank_tolerance, bool allow_avx2)
    : rows_(rows), n_(n), tol_(rank_tolerance), avx2_(allow_avx2 && haveAvx2()) {
  if (rows < 0 || n <= 0) throw std::invalid_argument("PriorityGramFactor: bad size");
  if (!(rank_tolerance > 0) || !(rank_tolerance < 1))
    throw std::invalid_argument("PriorityGramFactor: rank tolerance must be in (0, 1)");
  L_.setZero(rows, rows);
  d_.setZero(rows);
  v_.setZero(rows);
  y_.setZero(rows);
  t_.setZero(n);
}

void PriorityGramFactor::compute(const Eigen::Ref<const MatrixX>& G) {
  if (G.rows() != rows_ || G.cols() != rows_)
    throw std::invalid_argument("PriorityGramFactor::compute: G is " + std::to_string(G.rows()) + "x" +
                                std::to_string(G.cols()) + ", expected " + std::to_string(rows_) + "x" + std::to_string(rows_));
  // right-looking (outer-product) LDLᵀ on the lower triangle, in place in L_: at step k, column k
  // below the diagonal holds the Schur complement's column; it becomes L's column k (÷ d_k) and is
  // removed from the trailing block (independent column updates: no dependency chain through the
  // divisions, unlike the row-by-row form)
  L_.triangularView<Eigen::Lower>() = G.triangularView<Eigen::Lower>();
  double gmax = 0.0;
  for (int k = 0; k < rows_; ++k) {
    const double gkk = G(k, k);
    if (std::isfinite(gkk)) gmax = std::max(gmax, gkk);
    const double dk = L_(k, k);
    const int r = rows_ - k - 1;
    auto col = L_.col(k).tail(r);
    if (!(std::isfinite(dk) && dk > tol_ * gmax)) {  // row k depends on the rows before it: dropped
      d_(k) = 0.0;
      col.setZero();
      continue;
    }
    d_(k) = dk;
    const Eigen::Index ld = L_.outerStride();
    double* lk = L_.data() + k * ld + k + 1;  // column k below the diagonal
    double* v = v_.data();
    const double inv = 1.0 / dk;
    for (int i = 0; i < r; ++i) {
      v[i] = lk[i];       // the Schur column before scaling: A_ik
      lk[i] = v[i] * inv;  // L_ik
    }
    if (avx2_)
      schurUpdateAvx2(L_.data(), ld, k, r, lk, v);
    else
      schurUpdatePortable(L_.data(), ld, k, r, lk, v);
  }
}

void PriorityGramFactor::projectTorque(const Eigen::Ref<const MatrixX>& J, const VectorX& w_inv, int m, const VectorX& g,
                                       VectorX& out) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(J.rows(), rows_, "Jacobian J's rows");
  MANNEQUIN_CHECK_ARGUMENT_SIZE(J.cols(), n_, "Jacobian J's columns");
  MANNEQUIN_CHECK_ARGUMENT_SIZE(w_inv.size(), n_, "inverse weights w_inv");
  MANNEQUIN_CHECK_ARGUMENT_SIZE(g.size(), n_, "torque g");
  if (m < 0 || m > rows_)
    throw std::invalid_argument("PriorityGramFactor::projectTorque: m = " + std::to_string(m) + ", expected 0 to " + std::to_string(rows_));
  if (m == 0) {
    if (&out != &g) out = g;
    return;
  }
  // y = J_m W⁻¹ g; z = L⁻ᵀ D⁺ L⁻¹ y (the leading m × m part of L); out = g − J_mᵀ z
  t_ = w_inv.cwiseProduct(g);
  auto y = y_.head(m);
  y.noalias() = J.topRows(m) * t_;
  for (int k = 0; k + 1 < m; ++k) y.tail(m - k - 1) -= y(k) * L_.col(k).segment(k + 1, m - k - 1);
  for (int k = 0; k < m; ++k) y(k) = d_(k) > 0.0 ? y(k) / d_(k) : 0.0;
  for (int k = m - 2; k >= 0; --k) y(k) -= L_.col(k).segment(k + 1, m - k - 1).dot(y.tail(m - k - 1));
  t_.noalias() = J.topRows(m).transpose() * y;
  out = g - t_;
}

int PriorityGramFactor::rank(int m) const {
  int r = 0;
  for (int k = 0; k < std::min(m, rows_); ++k) r += d_(k) > 0.0 ? 1 : 0;
  return r;
}

AugmentedImpedance augmentedImpedance(const MatrixX& J, const VectorX& b_a_diag, double rank_tolerance) {
  if (b_a_diag.size() != J.cols() || (b_a_diag.array() <= 0).any())
    throw std::invalid_argument("augmentedImpedance: b_a must be a positive vector of J's column count");
  const Eigen::JacobiSVD<MatrixX> svd(J, Eigen::ComputeFullV);
  const auto& s = svd.singularValues();
  int rank = 0;
  for (Eigen::Index i = 0; i < s.size(); ++i)
    if (s(i) > rank_tolerance * s(0)) ++rank;
  AugmentedImpedance out;
  out.N = svd.matrixV().rightCols(J.cols() - rank);
  // J_int = (Nᵀ K N)⁻¹ Nᵀ K with K = b_a (2.39)
  const MatrixX NtK = out.N.transpose() * b_a_diag.asDiagonal();
  const MatrixX NtKN = NtK * out.N;
  out.J_int = NtKN.llt().solve(NtK);
  return out;
}

}  // namespace mannequin::control
