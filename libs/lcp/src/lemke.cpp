#include "mannequin/lcp/lemke.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace mannequin::lcp {

void LemkeWorkspace::resize(Index n) {
  if (n == n_) return;
  n_ = n;
  tableau_.resize(n, n + 1);
  rhs_.resize(n);
  col_.resize(n);
  row_.resize(n + 1);
  cover_.resize(n);
  resid_.resize(n);
  delta_.resize(n);
  basic_.assign(static_cast<std::size_t>(n), 0);
  nonbasic_.assign(static_cast<std::size_t>(n + 1), 0);
  where_.assign(static_cast<std::size_t>(2 * n + 1), 0);
  ties_.reserve(static_cast<std::size_t>(n));
  keep_.reserve(static_cast<std::size_t>(n));
}

// the pivoting engine; variables are numbered w_i = i, z_i = n + i, z0 = 2n
struct LemkeSolver {
  LemkeWorkspace& ws;
  const Eigen::MatrixXd& M;
  const Eigen::VectorXd& q;
  const LemkeOptions& opt;
  double pivot_tolerance;  // opt's, or a retry's
  Index n;
  int z0;
  double scale = 1.0;
  double min_rel_pivot = 1.0;  // smallest |pivot| / ‖column‖∞ met on the path

  static std::size_t u(Index i) { return static_cast<std::size_t>(i); }

  // entry (i, j) of B⁻¹: the tableau column of w_j, or a unit column when w_j is basic
  double binv(Index i, Index j) const {
    const int pos = ws.where_[u(j)];
    if (pos >= 0) return pos == i ? 1.0 : 0.0;
    return ws.tableau_(i, -pos - 1);
  }

  // fresh tableau: basis w, non-basic columns z (−M) then z0 (−d)
  void setup() {
    ws.tableau_.leftCols(n) = -M;
    ws.tableau_.col(n) = -ws.cover_;
    ws.rhs_ = q;
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
  void pivot(Index r, Index c) {
    Eigen::MatrixXd& T = ws.tableau_;
    const double piv = T(r, c);
    ws.col_ = T.col(c);
    ws.row_ = T.row(r).transpose() / piv;
    ws.col_[r] = 0.0;
    // rank-one update of every other row
    T.noalias() -= ws.col_ * ws.row_.transpose();
    T.row(r) = ws.row_.transpose();
    // the leaving variable's column
    T.col(c) = ws.col_ / (-piv);
    T(r, c) = 1.0 / piv;
    // basic values
    const double xr = ws.rhs_[r] / piv;
    ws.rhs_.noalias() -= xr * ws.col_;
    ws.rhs_[r] = xr;
    // bookkeeping
    const int entering = ws.nonbasic_[u(c)];
    const int leaving = ws.basic_[u(r)];
    ws.basic_[u(r)] = entering;
    ws.where_[u(entering)] = static_cast<int>(r);
    ws.nonbasic_[u(c)] = leaving;
    ws.where_[u(leaving)] = static_cast<int>(-(c + 1));
  }

  // lexicographic minimum ratio test on column c; −1 means no blocking row (a ray)
  Index ratioTest(Index c) {
    const auto col = ws.tableau_.col(c);
    const double tol = pivot_tolerance * std::max(col.cwiseAbs().maxCoeff(), scale);
    // minimum ratio over the blocking rows
    double best = std::numeric_limits<double>::infinity();
    for (Index i = 0; i < n; ++i) {
      if (col[i] > tol) best = std::min(best, std::max(ws.rhs_[i], 0.0) / col[i]);
    }
    if (!std::isfinite(best)) return -1;
    const double colmax = col.cwiseAbs().maxCoeff();
    // rows tied with it; z0 leaving ends the solve, so it wins any tie
    const double tie = best + opt.tie_tolerance * std::max(1.0, best);
    ws.ties_.clear();
    for (Index i = 0; i < n; ++i) {
      if (col[i] > tol && std::max(ws.rhs_[i], 0.0) / col[i] <= tie) {
        if (ws.basic_[u(i)] == z0) return i;
        ws.ties_.push_back(static_cast<int>(i));
      }
    }
    // break ties on the rows of B⁻¹ divided by the pivot entry, column by column
    for (Index j = 0; j < n && ws.ties_.size() > 1; ++j) {
      const int pos = ws.where_[u(j)];
      if (pos >= 0) {
        // unit column: its row has a positive entry, all others zero
        auto it = std::find(ws.ties_.begin(), ws.ties_.end(), pos);
        if (it != ws.ties_.end()) ws.ties_.erase(it);
        continue;
      }
      double vmin = std::numeric_limits<double>::infinity();
      for (int i : ws.ties_) vmin = std::min(vmin, binv(i, j) / col[i]);
      const double vtol = opt.tie_tolerance * std::max(1.0, std::abs(vmin));
      ws.keep_.clear();
      for (int i : ws.ties_) {
        if (binv(i, j) / col[i] <= vmin + vtol) ws.keep_.push_back(i);
      }
      ws.ties_.swap(ws.keep_);
    }
    // numerically indistinguishable rows left: take the largest pivot
    Index r = ws.ties_.front();
    for (int i : ws.ties_) {
      if (col[i] > col[r]) r = i;
    }
    min_rel_pivot = std::min(min_rel_pivot, col[r] / colmax);
    return r;
  }

  // one step of iterative refinement of the basic values: rhs += B⁻¹ (q − B rhs)
  void refine() {
    ws.resid_ = q;
    for (Index i = 0; i < n; ++i) {
      const int v = ws.basic_[u(i)];
      if (v < n) {
        ws.resid_[v] -= ws.rhs_[i];
      } else if (v < 2 * n) {
        ws.resid_.noalias() += M.col(v - n) * ws.rhs_[i];
      } else {
        ws.resid_.noalias() += ws.cover_ * ws.rhs_[i];
      }
    }
    ws.delta_.setZero();
    for (Index j = 0; j < n; ++j) {
      const int pos = ws.where_[u(j)];
      if (pos >= 0) {
        ws.delta_[pos] += ws.resid_[j];
      } else {
        ws.delta_.noalias() += ws.tableau_.col(-pos - 1) * ws.resid_[j];
      }
    }
    ws.rhs_ += ws.delta_;
  }

  // z from the basic values, clamped at 0
  void extract(Eigen::VectorXd& z) const {
    z.setZero(n);
    for (Index i = 0; i < n; ++i) {
      const int v = ws.basic_[u(i)];
      if (v >= n && v < 2 * n) z[v - n] = std::max(0.0, ws.rhs_[i]);
    }
  }
};

namespace {

// fills w = Mz + q and the residuals; keeps everything finite
void finish(const LcpProblem& p, LcpResult& res) {
  if (!res.z.allFinite()) res.z.setZero(p.q.size());
  res.w.noalias() = p.M * res.z;
  res.w += p.q;
  res.residuals = computeResiduals(p.q, res.z, res.w);
}

}  // namespace

namespace {

// one complementary pivoting run with covering vector workspace.cover_ already set and the given
// pivot tolerance (the retries change it), written into res
void lemkeAttempt(const LcpProblem& problem, LemkeWorkspace& workspace, const LemkeOptions& options,
                  double pivot_tolerance, LcpResult& res);

// an answer with no solution vectors (invalid input)
LcpStatus invalid(LcpResult& res, const char* message) {
  res.status = LcpStatus::Invalid;
  res.message = message;
  res.z.resize(0);
  res.w.resize(0);
  res.pivots = 0;
  res.residuals = LcpResiduals{};
  return res.status;
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
  // input checks
  if (const char* err = validate(problem)) return invalid(res, err);
  const Index n = problem.q.size();
  if (options.covering.size() != 0 &&
      (options.covering.size() != n || !options.covering.allFinite() ||
       options.covering.minCoeff() <= 0.0)) {
    return invalid(res, "covering vector must have n finite positive entries");
  }
  if (!(options.pivot_tolerance >= 0.0) || !(options.tie_tolerance >= 0.0) ||
      options.max_pivots < 0) {
    return invalid(res, "negative tolerance or pivot limit");
  }
  // trivial solution z = 0 when q ≥ 0
  if (n == 0 || problem.q.minCoeff() >= 0.0) {
    res.z.setZero(n);
    res.pivots = 0;
    res.status = LcpStatus::Solved;
    res.message = "q >= 0: z = 0";
    finish(problem, res);
    return res.status;
  }
  workspace.resize(n);
  if (options.covering.size() == n) {
    workspace.cover_ = options.covering;
  } else {
    workspace.cover_.setOnes();
  }
  lemkeAttempt(problem, workspace, options, options.pivot_tolerance, res);
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
        workspace.cover_[i] = (options.covering.size() == n ? options.covering[i] : 1.0) * (0.5 + frac);
      }
    }
    LcpResult& retry = workspace.retry_;
    lemkeAttempt(problem, workspace, options, pivot_tolerance, retry);
    total += retry.pivots;
    if (retry.status == LcpStatus::Solved || retry.status == res.status) std::swap(res, retry);
  }
  res.pivots = total;
  return res.status;
}

namespace {

void lemkeAttempt(const LcpProblem& problem, LemkeWorkspace& workspace, const LemkeOptions& options,
                  double pivot_tolerance, LcpResult& res) {
  const Index n = problem.q.size();
  LemkeSolver s{workspace, problem.M, problem.q, options, pivot_tolerance, n, static_cast<int>(2 * n)};
  s.scale = std::max(problem.M.cwiseAbs().maxCoeff(), workspace.cover_.maxCoeff());
  s.setup();
  const int max_pivots = options.max_pivots > 0 ? options.max_pivots
                                                : static_cast<int>(100 * n + 1000);

  // first pivot: z0 enters at the most negative q_i/d_i (ties: largest index, lexicographic)
  Index r = 0;
  double best = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < n; ++i) {
    const double ratio = problem.q[i] / workspace.cover_[i];
    if (ratio <= best) {
      best = ratio;
      r = i;
    }
  }
  int leaving = workspace.basic_[static_cast<std::size_t>(r)];
  s.pivot(r, n);
  int pivots = 1;

  // complementary pivoting
  res.status = LcpStatus::PivotLimit;
  res.message = "pivot limit reached";
  while (pivots < max_pivots) {
    const int entering = leaving < n ? static_cast<int>(leaving + n) : static_cast<int>(leaving - n);
    const Index c = -workspace.where_[static_cast<std::size_t>(entering)] - 1;
    r = s.ratioTest(c);
    if (r < 0) {
      // a degenerate ray met with z0 already at 0 still ends on a complementary solution
      const double z0_value = workspace.rhs_[workspace.where_[static_cast<std::size_t>(s.z0)]];
      if (z0_value <= options.tie_tolerance * (1.0 + problem.q.lpNorm<Eigen::Infinity>())) {
        s.extract(res.z);
        finish(problem, res);
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
    ++pivots;
    if (leaving == s.z0) {
      res.status = LcpStatus::Solved;
      res.message = "solved";
      break;
    }
  }
  res.pivots = pivots;

  // polish the final basis, then check the answer against the original data
  if (res.status == LcpStatus::Solved) {
    for (int k = 0; k < options.refinement_steps; ++k) s.refine();
  }
  s.extract(res.z);
  finish(problem, res);
  if (res.status == LcpStatus::Solved && !isComplementary(res.residuals, options.check_tolerance)) {
    res.status = LcpStatus::NumericalFailure;
    res.message = "final basis fails the residual check (ill-conditioned pivots)";
  }
}

}  // namespace

}  // namespace mannequin::lcp
