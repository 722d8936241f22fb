// g++ 12 reports false maybe-uninitialized warnings inside Eigen's self-adjoint kernels
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include "mannequin/lcp/structured.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mannequin::lcp {

namespace {

std::size_t u(Index i) { return static_cast<std::size_t>(i); }

// Givens pair (c, s) with [c s; −s c] [a; b] = [h; 0]
void givens(double a, double b, double& c, double& s) {
  const double h = std::hypot(a, b);
  if (h == 0.0) {
    c = 1.0;
    s = 0.0;
  } else {
    c = a / h;
    s = b / h;
  }
}

// J ← J Gᵀ on columns (j, k)
void rotateColumns(Eigen::Block<Eigen::MatrixXd>& J, Index j, Index k, double c, double s) {
  for (Index i = 0; i < J.rows(); ++i) {
    const double a = J(i, j), b = J(i, k);
    J(i, j) = c * a + s * b;
    J(i, k) = -s * a + c * b;
  }
}

}  // namespace

void StructuredWorkspace::reserve(Index n_capacity, Index m_capacity) {
  if (n_capacity <= n_cap_ && m_capacity <= m_cap_) return;
  n_cap_ = std::max(n_cap_, n_capacity);
  m_cap_ = std::max(m_cap_, m_capacity);
  const Index n = n_cap_, m = m_cap_;
  J_.resize(m, m);
  R_.resize(m, m);
  x_.resize(m);
  s_.resize(n);
  dir_.resize(m);
  d_.resize(m);
  r_.resize(m);
  u_.resize(m);
  as_.resize(n);
  norms_.resize(n);
  active_.reserve(u(m));
  previous_.reserve(u(m));
  is_active_.reserve(u(n));
  hinted_.reserve(u(n));
}

void StructuredWorkspace::resize(Index n, Index m) {
  if (n == n_ && m == m_) return;
  reserve(n, m);
  n_ = n;
  m_ = m;
  previous_.clear();
  is_active_.assign(u(n), 0);
  hinted_.assign(u(n), 0);
}

namespace {

LcpStatus fail(LcpResult& res, const char* message) {
  res.status = LcpStatus::Invalid;
  res.message = message;
  res.pivots = 0;
  res.residuals = LcpResiduals{};
  return res.status;
}

const char* check(const MatrixView& A, const VectorView& q, const StructuredOptions& options) {
  if (q.size() != A.rows()) return "q and A row counts differ";
  if (!A.allFinite() || !q.allFinite()) return "A or q has a NaN or Inf entry";
  if (options.max_iterations < 0 || !(options.dependence_tolerance >= 0.0) ||
      !(options.feasibility_tolerance >= 0.0)) {
    return "negative tolerance or iteration limit";
  }
  return nullptr;
}

// the dual active-set method on views, into the first n entries of res.z, res.w
LcpStatus solveViews(const MatrixView& A, const VectorView& q, StructuredWorkspace& ws,
                     const StructuredOptions& options, LcpResult& res) {
  const Index n = A.rows();
  const Index m = A.cols();
  ws.resize(n, m);
  auto J = ws.J_.topLeftCorner(m, m);
  auto R = ws.R_.topLeftCorner(m, m);
  auto x = ws.x_.head(m);
  auto s = ws.s_.head(n);
  auto dir = ws.dir_.head(m);
  auto dvec = ws.d_.head(m);
  auto rvec = ws.r_.head(m);
  auto uvec = ws.u_.head(m);
  auto as = ws.as_.head(n);
  auto norms = ws.norms_.head(n);
  const bool warm = options.warm_start;
  // start at the unconstrained minimum x = 0 with nothing active
  J.setIdentity();
  x.setZero();
  s = q;
  norms = A.rowwise().norm();
  std::fill(ws.is_active_.begin(), ws.is_active_.end(), 0);
  std::fill(ws.hinted_.begin(), ws.hinted_.end(), 0);
  if (warm) {
    for (int i : ws.previous_) ws.hinted_[u(i)] = 1;
  }
  ws.active_.clear();
  Index na = 0;
  const double feas = options.feasibility_tolerance * (1.0 + q.lpNorm<Eigen::Infinity>());
  const int max_iter = options.max_iterations > 0 ? options.max_iterations
                                                  : static_cast<int>(10 * (n + m) + 100);
  const double inf = std::numeric_limits<double>::infinity();
  int iter = 0;
  res.status = LcpStatus::Solved;
  res.message = "solved";

  // removes active position k, restoring R to triangular form
  auto drop = [&](Index k) {
    ws.is_active_[u(ws.active_[u(k)])] = 0;
    for (Index j = k; j + 1 < na; ++j) {
      R.col(j).head(na) = R.col(j + 1).head(na);
      ws.active_[u(j)] = ws.active_[u(j + 1)];
      uvec[j] = uvec[j + 1];
    }
    ws.active_.pop_back();
    for (Index j = k; j + 1 < na; ++j) {
      double c, sn;
      givens(R(j, j), R(j + 1, j), c, sn);
      for (Index cc = j; cc + 1 < na; ++cc) {
        const double a = R(j, cc), b = R(j + 1, cc);
        R(j, cc) = c * a + sn * b;
        R(j + 1, cc) = -sn * a + c * b;
      }
      R(j + 1, j) = 0.0;
      rotateColumns(J, j, j + 1, c, sn);
    }
    --na;
  };

  bool done = false;
  while (!done) {
    // most violated row (normalised), hinted rows first
    Index p = -1;
    for (int pass = warm ? 0 : 1; pass < 2 && p < 0; ++pass) {
      double worst = 0.0;
      for (Index i = 0; i < n; ++i) {
        if (ws.is_active_[u(i)] || (pass == 0 && !ws.hinted_[u(i)])) continue;
        if (s[i] < -feas && norms[i] > 0.0) {
          const double v = s[i] / norms[i];
          if (v < worst) {
            worst = v;
            p = i;
          }
        } else if (s[i] < -feas) {
          p = i;  // zero row with q_i < 0: infeasible, caught below
          break;
        }
      }
    }
    if (p < 0) break;
    double u_new = 0.0;
    const auto ap = A.row(p).transpose();
    const double ap_norm = norms[p];
    // steps towards satisfying row p
    for (;;) {
      if (++iter > max_iter) {
        res.status = LcpStatus::PivotLimit;
        res.message = "iteration limit reached";
        done = true;
        break;
      }
      dvec.noalias() = J.transpose() * ap;
      const Index free = m - na;
      const double d2 = free > 0 ? dvec.tail(free).norm() : 0.0;
      const bool dependent = d2 <= options.dependence_tolerance * ap_norm;
      if (!dependent) dir.noalias() = J.rightCols(free) * dvec.tail(free);
      // back substitution r = R⁻¹ d₁
      for (Index i = na - 1; i >= 0; --i) {
        double acc = dvec[i];
        for (Index j = i + 1; j < na; ++j) acc -= R(i, j) * rvec[j];
        rvec[i] = acc / R(i, i);
      }
      // partial (dual) step length: first active multiplier to reach 0
      double t1 = inf;
      Index k = -1;
      for (Index j = 0; j < na; ++j) {
        if (rvec[j] > 0.0 && uvec[j] / rvec[j] < t1) {
          t1 = uvec[j] / rvec[j];
          k = j;
        }
      }
      // full step length: row p becomes tight
      const double t2 = dependent ? inf : -s[p] / (d2 * d2);
      if (t1 == inf && t2 == inf) {
        res.status = LcpStatus::NoSolution;
        res.message = "constraints A x + q >= 0 are infeasible: no solution";
        done = true;
        break;
      }
      const double t = std::min(t1, t2);
      // update the multipliers (and the primal point when the row is independent)
      for (Index j = 0; j < na; ++j) uvec[j] -= t * rvec[j];
      u_new += t;
      if (!dependent) {
        x.noalias() += t * dir;
        as.noalias() = A * dir;
        s.noalias() += t * as;
      }
      if (t2 <= t1) {
        // add row p: rotate d so only its first na+1 entries are non-zero
        for (Index j = m - 1; j > na; --j) {
          double c, sn;
          givens(dvec[j - 1], dvec[j], c, sn);
          dvec[j - 1] = c * dvec[j - 1] + sn * dvec[j];
          dvec[j] = 0.0;
          rotateColumns(J, j - 1, j, c, sn);
        }
        R.col(na).head(na + 1) = dvec.head(na + 1);
        uvec[na] = u_new;
        ws.active_.push_back(static_cast<int>(p));
        ws.is_active_[u(p)] = 1;
        ++na;
        break;
      }
      uvec[k] = 0.0;
      drop(k);
    }
  }
  res.pivots = iter;
  ws.previous_.assign(ws.active_.begin(), ws.active_.end());

  // z from the multipliers; x and w recomputed from the data
  auto z = res.z.head(n);
  auto w = res.w.head(n);
  z.setZero();
  for (Index j = 0; j < na; ++j) z[ws.active_[u(j)]] = std::max(0.0, uvec[j]);
  if (!z.allFinite()) {
    z.setZero();
    res.status = LcpStatus::NumericalFailure;
    res.message = "non-finite multipliers";
  }
  x.noalias() = A.transpose() * z;
  w.noalias() = A * x;
  w += q;
  res.residuals = computeResiduals(q, z, w);
  if (res.status == LcpStatus::Solved && !isComplementary(res.residuals, options.check_tolerance)) {
    res.status = LcpStatus::NumericalFailure;
    res.message = "active set fails the residual check";
  }
  return res.status;
}

}  // namespace

LcpResult solveStructured(const StructuredProblem& problem, StructuredWorkspace& ws,
                          const StructuredOptions& options) {
  LcpResult res;
  if (const char* err = check(problem.A, problem.q, options)) {
    fail(res, err);
    return res;
  }
  res.z.resize(problem.q.size());
  res.w.resize(problem.q.size());
  solveViews(problem.A, problem.q, ws, options, res);
  return res;
}

LcpStatus solveStructured(const MatrixView& A, const VectorView& q, StructuredWorkspace& workspace,
                          const StructuredOptions& options, LcpResult& result) {
  if (const char* err = check(A, q, options)) return fail(result, err);
  if (result.z.size() < q.size() || result.w.size() < q.size()) {
    return fail(result, "result.z and result.w need at least n entries (LcpResult::reserve)");
  }
  return solveViews(A, q, workspace, options, result);
}

const char* factorPsd(const Eigen::MatrixXd& M, Eigen::MatrixXd& A, double rank_tol) {
  if (M.rows() != M.cols()) return "M is not square";
  if (!M.allFinite()) return "M has a NaN or Inf entry";
  const double scale = M.cwiseAbs().maxCoeff();
  if ((M - M.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1.0 + scale)) {
    return "M is not symmetric, so not of the form A A^T";
  }
  if (M.rows() == 0) {
    A.resize(0, 0);
    return nullptr;
  }
  // eigenvalues ascending; keep the ones above the rank threshold
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (M + M.transpose()));
  if (eig.info() != Eigen::Success) return "eigendecomposition of M failed";
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const double lmax = std::max(lambda.maxCoeff(), 0.0);
  const double cut = rank_tol * std::max(lmax, 1e-300);
  if (lambda.minCoeff() < -std::max(cut, 1e-14 * (1.0 + scale))) {
    return "M is not positive semidefinite (negative eigenvalue)";
  }
  Index r = 0;
  for (Index i = 0; i < lambda.size(); ++i) r += lambda[i] > cut ? 1 : 0;
  A = eig.eigenvectors().rightCols(r) * lambda.tail(r).cwiseSqrt().asDiagonal();
  return nullptr;
}

}  // namespace mannequin::lcp
