#include "mannequin/lcp/lemke.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace mannequin::lcp {

void LemkeWorkspace::reserve(Index capacity) {
  if (capacity <= capacity_) return;
  capacity_ = capacity;
  tableau_.resize(capacity, capacity + 1);
  rhs_.resize(capacity);
  col_.resize(capacity);
  row_.resize(capacity + 1);
  cover_.resize(capacity);
  resid_.resize(capacity);
  delta_.resize(capacity);
  basic_.reserve(static_cast<std::size_t>(capacity));
  nonbasic_.reserve(static_cast<std::size_t>(capacity + 1));
  where_.reserve(static_cast<std::size_t>(2 * capacity + 1));
  ties_.reserve(static_cast<std::size_t>(capacity));
  keep_.reserve(static_cast<std::size_t>(capacity));
  eta_row_.reserve(static_cast<std::size_t>(capacity + 1));
  tie_col_.reserve(static_cast<std::size_t>(capacity));
  retry_.reserve(capacity);
  warm_idx_.reserve(static_cast<std::size_t>(capacity));
  basis_.resize(static_cast<std::size_t>(capacity), 0);
  warm_perm_.reserve(static_cast<std::size_t>(capacity));
}

void LemkeWorkspace::resize(Index n) {
  if (n == n_) return;
  reserve(n);
  n_ = n;
  basic_.assign(static_cast<std::size_t>(n), 0);
  nonbasic_.assign(static_cast<std::size_t>(n + 1), 0);
  where_.assign(static_cast<std::size_t>(2 * n + 1), 0);
}

namespace {
// a dense M as an operator
class DenseMatrix final : public LcpMatrixOperator {
 public:
  explicit DenseMatrix(const MatrixView& M) : M_(M) {}  // a view of M (no copy)
  Index size() const override { return M_.rows(); }
  void column(Index j, Eigen::Ref<Eigen::VectorXd> out) const override { out = M_.col(j); }
  void multiply(const VectorView& z, Eigen::Ref<Eigen::VectorXd> out) const override { out.noalias() = M_ * z; }
  double maxAbs() const override { return M_.size() > 0 ? M_.cwiseAbs().maxCoeff() : 0.0; }

 private:
  MatrixView M_;
};
}  // namespace

// the pivoting engine; variables are numbered w_i = i, z_i = n + i, z0 = 2n
struct LemkeSolver {
  using Tableau = Eigen::Block<Eigen::MatrixXd>;
  using Segment = Eigen::VectorBlock<Eigen::VectorXd>;
  LemkeWorkspace& ws;
  const LcpMatrixOperator& M;
  const VectorView& q;
  const LemkeOptions& opt;
  double pivot_tolerance;  // opt's, or a retry's
  Index n;
  int z0;
  // the leading blocks of the workspace's capacity-sized buffers
  Tableau T{ws.tableau_, 0, 0, n, n + 1};
  Segment rhs{ws.rhs_, 0, n}, col{ws.col_, 0, n}, row{ws.row_, 0, n + 1}, cover{ws.cover_, 0, n},
      resid{ws.resid_, 0, n}, delta{ws.delta_, 0, n};
  double scale = 1.0;
  double min_rel_pivot = 1.0;  // smallest |pivot| / ‖column‖∞ met on the path
  bool product = false;        // product form (eta file in the tableau's columns)
  bool overflow = false;       // product form: the eta file is full (restart dense)
  Index etas = 0;              // product form: eta columns in use
  Index tie_cols = 0;          // product form: B⁻¹ rows cached from the right end

  static std::size_t u(Index i) { return static_cast<std::size_t>(i); }

  // the full workspace buffer (product form: etas and cached rows, n rows each)
  Eigen::MatrixXd& W() { return ws.tableau_; }

  // entry (i, j) of B⁻¹: the tableau column of w_j, or a unit column when w_j is basic
  double binv(Index i, Index j) const {
    const int pos = ws.where_[u(j)];
    if (pos >= 0) return pos == i ? 1.0 : 0.0;
    if (product) return ws.tableau_(j, ws.tie_col_[u(i)]);
    return T(i, -pos - 1);
  }

  // product form: v ← E_k ⋯ E_1 v (B⁻¹ v)
  template <typename V>
  void applyEtas(V&& v) const {
    for (Index k = 0; k < etas; ++k) {
      const Index r = ws.eta_row_[u(k)];
      const auto d = ws.tableau_.col(k).head(n);
      const double t = v[r] / d[r];
      if (t != 0.0) v.noalias() -= t * d;
      v[r] = t;
    }
  }

  // product form: the column of B⁻¹ [I, −M, −d] for the non-basic column c, into `col`
  void column(Index c) {
    const int var = ws.nonbasic_[u(c)];
    if (var < n) {
      col.setZero();
      col[var] = 1.0;
    } else if (var < 2 * n) {
      M.column(var - n, col);
      col = -col;
    } else {
      col = -cover;
    }
    applyEtas(col);
  }

  // product form: row i of B⁻¹ (eᵢᵀ E_k ⋯ E_1) cached in a column from the right end of the buffer;
  // false when the buffer is full
  bool cacheRow(Index i) {
    if (ws.tie_col_[u(i)] >= 0) return true;
    const Index c = W().cols() - 1 - tie_cols;
    if (c < etas) return false;
    ++tie_cols;
    ws.tie_col_[u(i)] = static_cast<int>(c);
    auto v = W().col(c).head(n);
    v.setZero();
    v[i] = 1.0;
    for (Index k = etas - 1; k >= 0; --k) {
      const Index r = ws.eta_row_[u(k)];
      const auto d = ws.tableau_.col(k).head(n);
      v[r] = (v[r] - v.dot(d) + v[r] * d[r]) / d[r];
    }
    return true;
  }

  // fresh tableau: basis w, non-basic columns z (−M) then z0 (−d)
  void setup() {
    if (product) {
      etas = 0;
      ws.eta_row_.clear();
      ws.tie_col_.assign(u(n), -1);
    } else {
      for (Index j = 0; j < n; ++j) {
        M.column(j, T.col(j));
        T.col(j) = -T.col(j);
      }
      T.col(n) = -cover;
    }
    rhs = q;
    for (Index i = 0; i < n; ++i) {
      ws.basic_[u(i)] = static_cast<int>(i);
      ws.where_[u(i)] = static_cast<int>(i);
      ws.nonbasic_[u(i)] = static_cast<int>(n + i);
      ws.where_[u(n + i)] = static_cast<int>(-(i + 1));
    }
    ws.nonbasic_[u(n)] = z0;
    ws.where_[u(z0)] = static_cast<int>(-(n + 1));
  }

  // Jordan exchange on (r, c), in place: the entering variable of column c becomes basic in
  // row r and the leaving one takes column c
  // product form: `col` holds the entering column (column(c)); it becomes an eta
  void pivot(Index r, Index c) {
    if (product) {
      if (etas >= W().cols() - tie_cols || (opt.max_etas > 0 && etas >= opt.max_etas)) {
        overflow = true;
        return;
      }
      const double piv = col[r];
      W().col(etas).head(n) = col;
      ws.eta_row_.push_back(static_cast<int>(r));
      ++etas;
      const double xr = rhs[r] / piv;
      rhs.noalias() -= xr * col;
      rhs[r] = xr;
      book(r, c);
      // the rows cached for ties belong to the old basis
      for (int& tc : ws.tie_col_) tc = -1;
      tie_cols = 0;
      return;
    }
    const double piv = T(r, c);
    col = T.col(c);
    row = T.row(r).transpose() / piv;
    col[r] = 0.0;
    // rank-one update of every other row
    T.noalias() -= col * row.transpose();
    T.row(r) = row.transpose();
    // the leaving variable's column
    T.col(c) = col / (-piv);
    T(r, c) = 1.0 / piv;
    // basic values
    const double xr = rhs[r] / piv;
    rhs.noalias() -= xr * col;
    rhs[r] = xr;
    book(r, c);
  }

  // bookkeeping of an exchange on (r, c)
  void book(Index r, Index c) {
    const int entering = ws.nonbasic_[u(c)];
    const int leaving = ws.basic_[u(r)];
    ws.basic_[u(r)] = entering;
    ws.where_[u(entering)] = static_cast<int>(r);
    ws.nonbasic_[u(c)] = leaving;
    ws.where_[u(leaving)] = static_cast<int>(-(c + 1));
  }

  // lexicographic minimum ratio test on column c; −1 means no blocking row (a ray)
  // (product form: on `col`, filled by column(c))
  Index ratioTest(Index c) {
    const auto column = product ? Eigen::Ref<const Eigen::VectorXd>(col) : Eigen::Ref<const Eigen::VectorXd>(T.col(c));
    const double tol = pivot_tolerance * std::max(column.cwiseAbs().maxCoeff(), scale);
    // minimum ratio over the blocking rows
    double best = std::numeric_limits<double>::infinity();
    for (Index i = 0; i < n; ++i) {
      if (column[i] > tol) best = std::min(best, std::max(rhs[i], 0.0) / column[i]);
    }
    if (!std::isfinite(best)) return -1;
    const double colmax = column.cwiseAbs().maxCoeff();
    // rows tied with it; z0 leaving ends the solve, so it wins any tie
    const double tie = best + opt.tie_tolerance * std::max(1.0, best);
    ws.ties_.clear();
    for (Index i = 0; i < n; ++i) {
      if (column[i] > tol && std::max(rhs[i], 0.0) / column[i] <= tie) {
        if (ws.basic_[u(i)] == z0) return i;
        ws.ties_.push_back(static_cast<int>(i));
      }
    }
    // break ties on the rows of B⁻¹ divided by the pivot entry, column by column
    if (product && ws.ties_.size() > 1) {
      for (int i : ws.ties_) {
        if (!cacheRow(i)) {
          overflow = true;
          return -1;
        }
      }
    }
    for (Index j = 0; j < n && ws.ties_.size() > 1; ++j) {
      const int pos = ws.where_[u(j)];
      if (pos >= 0) {
        // unit column: its row has a positive entry, all others zero
        auto it = std::find(ws.ties_.begin(), ws.ties_.end(), pos);
        if (it != ws.ties_.end()) ws.ties_.erase(it);
        continue;
      }
      double vmin = std::numeric_limits<double>::infinity();
      for (int i : ws.ties_) vmin = std::min(vmin, binv(i, j) / column[i]);
      const double vtol = opt.tie_tolerance * std::max(1.0, std::abs(vmin));
      ws.keep_.clear();
      for (int i : ws.ties_) {
        if (binv(i, j) / column[i] <= vmin + vtol) ws.keep_.push_back(i);
      }
      ws.ties_.swap(ws.keep_);
    }
    // numerically indistinguishable rows left: take the largest pivot
    Index r = ws.ties_.front();
    for (int i : ws.ties_) {
      if (column[i] > column[r]) r = i;
    }
    min_rel_pivot = std::min(min_rel_pivot, column[r] / colmax);
    return r;
  }

  // one step of iterative refinement of the basic values: rhs += B⁻¹ (q − B rhs)
  void refine() {
    resid = q;
    delta.setZero();  // the basic z's (scratch)
    for (Index i = 0; i < n; ++i) {
      const int v = ws.basic_[u(i)];
      if (v < n) {
        resid[v] -= rhs[i];
      } else if (v < 2 * n) {
        delta[v - n] = rhs[i];
      } else {
        resid.noalias() += cover * rhs[i];
      }
    }
    M.multiply(delta, col);  // col is free after the path
    resid += col;
    if (product) {
      delta = resid;
      applyEtas(delta);
      rhs += delta;
      return;
    }
    delta.setZero();
    for (Index j = 0; j < n; ++j) {
      const int pos = ws.where_[u(j)];
      if (pos >= 0) {
        delta[pos] += resid[j];
      } else {
        delta.noalias() += T.col(-pos - 1) * resid[j];
      }
    }
    rhs += delta;
  }

  // z from the basic values, clamped at 0
  void extract(Segment z) const {
    z.setZero();
    for (Index i = 0; i < n; ++i) {
      const int v = ws.basic_[u(i)];
      if (v >= n && v < 2 * n) z[v - n] = std::max(0.0, rhs[i]);
    }
  }
};

namespace {

// fills w = Mz + q and the residuals of z, w (n-entry views); keeps everything finite
void finish(const LcpMatrixOperator& M, const VectorView& q, Eigen::VectorBlock<Eigen::VectorXd> z,
            Eigen::VectorBlock<Eigen::VectorXd> w, LcpResult& res) {
  if (!z.allFinite()) z.setZero();
  M.multiply(z, w);
  w += q;
  res.residuals = computeResiduals(q, z, w);
}

// one complementary pivoting run with covering vector workspace.cover_ already set and the given
// pivot tolerance (the retries change it), written into the first n entries of res.z, res.w
void lemkeAttempt(const LcpMatrixOperator& M, const VectorView& q, LemkeWorkspace& workspace,
                  const LemkeOptions& options, double pivot_tolerance, LcpResult& res);
// one run in the requested form: the product form falls back to the dense one when its eta file
// is full (the pivots so far are counted)
bool lemkeRun(const LcpMatrixOperator& M, const VectorView& q, LemkeWorkspace& workspace, const LemkeOptions& options,
              double pivot_tolerance, bool product, LcpResult& res);

// an answer with no solution vectors (invalid input)
LcpStatus invalid(LcpResult& res, const char* message) {
  res.status = LcpStatus::Invalid;
  res.message = message;
  res.pivots = 0;
  res.residuals = LcpResiduals{};
  return res.status;
}

// the solve on views, into the first n entries of res.z, res.w (at least n entries each)
LcpStatus solveViews(const LcpMatrixOperator& M, const VectorView& q, LemkeWorkspace& workspace,
                     const LemkeOptions& options, LcpResult& res) {
  const Index n = q.size();
  // trivial solution z = 0 when q ≥ 0
  if (n == 0 || q.minCoeff() >= 0.0) {
    res.z.head(n).setZero();
    res.pivots = 0;
    res.status = LcpStatus::Solved;
    res.message = "q >= 0: z = 0";
    finish(M, q, res.z.head(n), res.w.head(n), res);
    if (workspace.capacity() >= n) std::fill_n(workspace.basis_.begin(), n, std::uint8_t{0});
    return res.status;
  }
  workspace.resize(n);
  auto cover = workspace.cover_.head(n);
  if (options.covering.size() == n) {
    cover = options.covering;
  } else {
    cover.setOnes();
  }
  lemkeAttempt(M, q, workspace, options, options.pivot_tolerance, res);
  // on rank-deficient M a near-singular basis can derail the path: retry with another
  // tolerance or along another path; a real ray comes back again and is reported
  int total = res.pivots;
  for (int k = 1; k <= options.retries && (res.status == LcpStatus::NoSolution ||
                                           res.status == LcpStatus::NumericalFailure); ++k) {
    // odd retries: another pivot tolerance on the same path; even ones: another path
    double pivot_tolerance = options.pivot_tolerance;
    if (k % 2 == 1) {
      pivot_tolerance *= k == 1 ? 100.0 : 0.01;
    } else {
      for (Index i = 0; i < n; ++i) {
        const double frac = std::fmod(0.6180339887498949 * static_cast<double>((i + 1) * (k + 1)), 1.0);
        cover[i] = (options.covering.size() == n ? options.covering[i] : 1.0) * (0.5 + frac);
      }
    }
    LcpResult& retry = workspace.retry_;
    retry.reserve(n);
    lemkeAttempt(M, q, workspace, options, pivot_tolerance, retry);
    total += retry.pivots;
    if (retry.status == LcpStatus::Solved || retry.status == res.status) {
      // copy (not swap): res keeps its own storage
      res.status = retry.status;
      res.message = retry.message;
      res.residuals = retry.residuals;
      res.z.head(n) = retry.z.head(n);
      res.w.head(n) = retry.w.head(n);
    }
  }
  res.pivots = total;
  if (res.status == LcpStatus::Solved) {  // the final basis (the last attempt's: a solved one ends the retries)
    std::fill_n(workspace.basis_.begin(), n, std::uint8_t{0});
    for (Index i = 0; i < n; ++i) {
      const int v = workspace.basic_[static_cast<std::size_t>(i)];
      if (v >= n && v < 2 * n) workspace.basis_[static_cast<std::size_t>(v - n)] = 1;
    }
  }
  return res.status;
}

// checks the options against n; nullptr when valid
const char* checkOptions(const LemkeOptions& options, Index n) {
  if (options.covering.size() != 0 &&
      (options.covering.size() != n || !options.covering.allFinite() ||
       options.covering.minCoeff() <= 0.0)) {
    return "covering vector must have n finite positive entries";
  }
  if (!(options.pivot_tolerance >= 0.0) || !(options.tie_tolerance >= 0.0) ||
      options.max_pivots < 0) {
    return "negative tolerance or pivot limit";
  }
  return nullptr;
}

}  // namespace

LcpResult solveLemke(const LcpProblem& problem, LemkeWorkspace& workspace,
                     const LemkeOptions& options) {
  LcpResult res;
  solveLemke(problem, workspace, options, res);
  return res;
}

LcpStatus solveLemke(const LcpProblem& problem, LemkeWorkspace& workspace, const LemkeOptions& options,
                     LcpResult& res) {
  const char* err = validate(problem);
  if (err == nullptr) err = checkOptions(options, problem.q.size());
  if (err != nullptr) {
    res.z.resize(0);
    res.w.resize(0);
    return invalid(res, err);
  }
  const Index n = problem.q.size();
  res.z.resize(n);
  res.w.resize(n);
  return solveViews(DenseMatrix(problem.M), problem.q, workspace, options, res);
}

LcpStatus solveLemke(const MatrixView& M, const VectorView& q, LemkeWorkspace& workspace,
                     const LemkeOptions& options, LcpResult& result) {
  const char* err = validate(M, q);
  if (err == nullptr) err = checkOptions(options, q.size());
  if (err == nullptr && (result.z.size() < q.size() || result.w.size() < q.size())) {
    err = "result.z and result.w need at least n entries (LcpResult::reserve)";
  }
  if (err != nullptr) return invalid(result, err);
  return solveViews(DenseMatrix(M), q, workspace, options, result);
}

namespace {

// In place LU with partial pivoting of A (k×k): A = P⁻¹ L U, perm[i] = original row of row i.
// False when a pivot is below tol (the guessed basis is singular or nearly so).
bool luInPlace(Eigen::Ref<Eigen::MatrixXd> A, std::vector<int>& perm, double tol) {
  const Index k = A.rows();
  perm.resize(static_cast<std::size_t>(k));
  for (Index i = 0; i < k; ++i) perm[static_cast<std::size_t>(i)] = static_cast<int>(i);
  for (Index j = 0; j < k; ++j) {
    Index p = j;
    A.col(j).tail(k - j).cwiseAbs().maxCoeff(&p);
    p += j;
    if (!(std::abs(A(p, j)) > tol)) return false;
    if (p != j) {
      A.row(p).swap(A.row(j));
      std::swap(perm[static_cast<std::size_t>(p)], perm[static_cast<std::size_t>(j)]);
    }
    const Index below = k - j - 1;
    A.col(j).tail(below) /= A(j, j);
    A.bottomRightCorner(below, below).noalias() -= A.col(j).tail(below) * A.row(j).tail(below);
  }
  return true;
}

// the guessed basis's answer into res (true when it passes the final check)
bool tryWarm(const LcpMatrixOperator& M, const VectorView& q, const std::uint8_t* basic, LemkeWorkspace& ws,
             const LemkeOptions& options, LcpResult& res) {
  const Index n = q.size();
  auto& idx = ws.warm_idx_;
  idx.clear();
  for (Index i = 0; i < n; ++i) {
    if (basic[i] != 0) idx.push_back(static_cast<int>(i));
  }
  const auto k = static_cast<Index>(idx.size());
  if (k == 0) return false;
  // the principal block and its LU in the tableau's buffer (free until Lemke's setup)
  auto A = ws.tableau_.topLeftCorner(k, k);
  auto scratch = ws.col_.head(n);
  M.principal(idx.data(), k, A, scratch);
  const double scale = std::max(M.maxAbs(), 1.0);
  if (!luInPlace(A, ws.warm_perm_, 1e-10 * scale)) return false;
  // z_B = −A⁻¹ q_B: forward (unit L) then back substitution, in ws.delta_
  auto x = ws.delta_.head(k);
  for (Index i = 0; i < k; ++i) x[i] = -q[idx[static_cast<std::size_t>(ws.warm_perm_[static_cast<std::size_t>(i)])]];
  A.triangularView<Eigen::UnitLower>().solveInPlace(x);
  A.triangularView<Eigen::Upper>().solveInPlace(x);
  auto z = res.z.head(n);
  z.setZero();
  const double neg_tol = options.check_tolerance * (1.0 + q.lpNorm<Eigen::Infinity>());
  for (Index i = 0; i < k; ++i) {
    if (!std::isfinite(x[i]) || x[i] < -neg_tol) return false;
    z[idx[static_cast<std::size_t>(i)]] = std::max(0.0, x[i]);
  }
  finish(M, q, z, res.w.head(n), res);
  return isComplementary(res.residuals, options.check_tolerance);
}

const char* checkOperator(const LcpMatrixOperator& M, const VectorView& q, const LemkeOptions& options,
                          const LcpResult& result) {
  const char* err = M.size() != q.size() ? "q and M sizes differ" : nullptr;
  if (err == nullptr && !q.allFinite()) err = "q has a NaN or Inf entry";
  if (err == nullptr) err = checkOptions(options, q.size());
  if (err == nullptr && (result.z.size() < q.size() || result.w.size() < q.size())) {
    err = "result.z and result.w need at least n entries (LcpResult::reserve)";
  }
  return err;
}

}  // namespace

LcpStatus solveLemkeWarm(const LcpMatrixOperator& M, const VectorView& q, const std::uint8_t* basic,
                         LemkeWorkspace& workspace, const LemkeOptions& options, LcpResult& result, bool* warm) {
  return solveLemkeWarm(M, q, basic, nullptr, workspace, options, result, warm);
}

LcpStatus solveLemkeWarm(const LcpMatrixOperator& M, const VectorView& q, const std::uint8_t* basic,
                         const std::uint8_t* second, LemkeWorkspace& workspace, const LemkeOptions& options,
                         LcpResult& result, bool* warm) {
  if (warm != nullptr) *warm = false;
  if (const char* err = checkOperator(M, q, options, result)) return invalid(result, err);
  workspace.resize(q.size());
  for (const std::uint8_t* guess : {basic, second}) {
    if (guess != nullptr && q.size() > 0 && tryWarm(M, q, guess, workspace, options, result)) {
      result.status = LcpStatus::Solved;
      result.message = guess == basic ? "solved (warm start: the guessed basis)" : "solved (warm start: the second guess)";
      result.pivots = 0;
      std::copy_n(guess, q.size(), workspace.basis_.begin());
      if (warm != nullptr) *warm = true;
      return result.status;
    }
  }
  return solveViews(M, q, workspace, options, result);
}

LcpStatus solveLemke(const LcpMatrixOperator& M, const VectorView& q, LemkeWorkspace& workspace,
                     const LemkeOptions& options, LcpResult& result) {
  const char* err = M.size() != q.size() ? "q and M sizes differ" : nullptr;
  if (err == nullptr && !q.allFinite()) err = "q has a NaN or Inf entry";
  if (err == nullptr) err = checkOptions(options, q.size());
  if (err == nullptr && (result.z.size() < q.size() || result.w.size() < q.size())) {
    err = "result.z and result.w need at least n entries (LcpResult::reserve)";
  }
  if (err != nullptr) return invalid(result, err);
  return solveViews(M, q, workspace, options, result);
}

namespace {

void lemkeAttempt(const LcpMatrixOperator& M, const VectorView& q, LemkeWorkspace& workspace,
                  const LemkeOptions& options, double pivot_tolerance, LcpResult& res) {
  if (options.product_form && lemkeRun(M, q, workspace, options, pivot_tolerance, true, res)) return;
  const int spent = options.product_form ? res.pivots : 0;
  lemkeRun(M, q, workspace, options, pivot_tolerance, false, res);
  res.pivots += spent;
}

bool lemkeRun(const LcpMatrixOperator& M, const VectorView& q, LemkeWorkspace& workspace, const LemkeOptions& options,
              double pivot_tolerance, bool product, LcpResult& res) {
  const Index n = q.size();
  LemkeSolver s{workspace, M, q, options, pivot_tolerance, n, static_cast<int>(2 * n)};
  s.product = product;
  auto z = res.z.head(n);
  auto w = res.w.head(n);
  s.scale = std::max(M.maxAbs(), s.cover.maxCoeff());
  s.setup();
  const int max_pivots = options.max_pivots > 0 ? options.max_pivots
                                                : static_cast<int>(100 * n + 1000);

  // first pivot: z0 enters at the most negative q_i/d_i (ties: largest index, lexicographic)
  Index r = 0;
  double best = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < n; ++i) {
    const double ratio = q[i] / s.cover[i];
    if (ratio <= best) {
      best = ratio;
      r = i;
    }
  }
  int leaving = workspace.basic_[static_cast<std::size_t>(r)];
  if (product) s.column(n);
  s.pivot(r, n);
  int pivots = 1;

  // complementary pivoting
  res.status = LcpStatus::PivotLimit;
  res.message = "pivot limit reached";
  while (pivots < max_pivots) {
    const int entering = leaving < n ? static_cast<int>(leaving + n) : static_cast<int>(leaving - n);
    const Index c = -workspace.where_[static_cast<std::size_t>(entering)] - 1;
    if (product) s.column(c);
    r = s.ratioTest(c);
    if (s.overflow) break;
    if (r < 0) {
      // a degenerate ray met with z0 already at 0 still ends on a complementary solution
      const double z0_value = s.rhs[workspace.where_[static_cast<std::size_t>(s.z0)]];
      if (z0_value <= options.tie_tolerance * (1.0 + q.lpNorm<Eigen::Infinity>())) {
        s.extract(z);
        finish(M, q, z, w, res);
        if (isComplementary(res.residuals, options.check_tolerance)) {
          res.status = LcpStatus::Solved;
          res.message = "solved (z0 reached 0 on a degenerate ray)";
          break;
        }
      }
      if (s.min_rel_pivot < options.unreliable_pivot) {
        res.status = LcpStatus::NumericalFailure;
        res.message = "ray reached after ill-conditioned pivots: no conclusion";
      } else {
        res.status = LcpStatus::NoSolution;
        res.message = "ray termination: no solution for this M, q";
      }
      break;
    }
    leaving = workspace.basic_[static_cast<std::size_t>(r)];
    s.pivot(r, c);
    if (s.overflow) break;
    ++pivots;
    if (leaving == s.z0) {
      res.status = LcpStatus::Solved;
      res.message = "solved";
      break;
    }
  }
  res.pivots = pivots;
  if (s.overflow) return false;

  // polish the final basis, then check the answer against the original data
  if (res.status == LcpStatus::Solved) {
    for (int k = 0; k < options.refinement_steps; ++k) s.refine();
  }
  s.extract(z);
  finish(M, q, z, w, res);
  if (res.status == LcpStatus::Solved && !isComplementary(res.residuals, options.check_tolerance)) {
    res.status = LcpStatus::NumericalFailure;
    res.message = "final basis fails the residual check (ill-conditioned pivots)";
  }
  return true;
}

}  // namespace

}  // namespace mannequin::lcp
