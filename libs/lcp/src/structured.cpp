// g++ 12 reports false maybe-uninitialized warnings inside Eigen's self-adjoint kernels
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
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
void rotateColumns(Eigen::MatrixXd& J, Index j, Index k, double c, double s) {
  for (Index i = 0; i < J.rows(); ++i) {
    const double a = J(i, j), b = J(i, k);
    J(i, j) = c * a + s * b;
    J(i, k) = -s * a + c * b;
  }
}

}  // namespace

void StructuredWorkspace::resize(Index n, Index m) {
  if (n == n_ && m == m_) return;
  n_ = n;
  m_ = m;
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
  previous_.clear();
  previous_.reserve(u(m));
  is_active_.assign(u(n), 0);
  hinted_.assign(u(n), 0);
}

LcpResult solveStructured(const StructuredProblem& problem, StructuredWorkspace& ws,
                          const StructuredOptions& options) {
  LcpResult res;
  // input checks
  const Index n = problem.A.rows();
  const Index m = problem.A.cols();
  if (problem.q.size() != n) {
    res.status = LcpStatus::Invalid;
    res.message = "q and A row counts differ";
    return res;
  }
  if (!problem.A.allFinite() || !problem.q.allFinite()) {
    res.status = LcpStatus::Invalid;
    res.message = "A or q has a NaN or Inf entry";
    return res;
  }
  if (options.max_iterations < 0 || !(options.dependence_tolerance >= 0.0) ||
      !(options.feasibility_tolerance >= 0.0)) {
    res.status = LcpStatus::Invalid;
    res.message = "negative tolerance or iteration limit";
    return res;
  }
  ws.resize(n, m);
  const bool warm = options.warm_start;
  // start at the unconstrained minimum x = 0 with nothing active
  ws.J_.setIdentity();
  ws.x_.setZero();
  ws.s_ = problem.q;
  ws.norms_ = problem.A.rowwise().norm();
  std::fill(ws.is_active_.begin(), ws.is_active_.end(), 0);
  std::fill(ws.hinted_.begin(), ws.hinted_.end(), 0);
  if (warm) {
    for (int i : ws.previous_) ws.hinted_[u(i)] = 1;
  }
  ws.active_.clear();
  Index na = 0;
  const double feas = options.feasibility_tolerance * (1.0 + problem.q.lpNorm<Eigen::Infinity>());
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
      ws.R_.col(j).head(na) = ws.R_.col(j + 1).head(na);
      ws.active_[u(j)] = ws.active_[u(j + 1)];
      ws.u_[j] = ws.u_[j + 1];
    }
    ws.active_.pop_back();
    for (Index j = k; j + 1 < na; ++j) {
      double c, s;
      givens(ws.R_(j, j), ws.R_(j + 1, j), c, s);
      for (Index cc = j; cc + 1 < na; ++cc) {
        const double a = ws.R_(j, cc), b = ws.R_(j + 1, cc);
        ws.R_(j, cc) = c * a + s * b;
        ws.R_(j + 1, cc) = -s * a + c * b;
      }
      ws.R_(j + 1, j) = 0.0;
      rotateColumns(ws.J_, j, j + 1, c, s);
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
        if (ws.s_[i] < -feas && ws.norms_[i] > 0.0) {
          const double v = ws.s_[i] / ws.norms_[i];
          if (v < worst) {
            worst = v;
            p = i;
          }
        } else if (ws.s_[i] < -feas) {
          p = i;  // zero row with q_i < 0: infeasible, caught below
          break;
        }
      }
    }
    if (p < 0) break;
    double u_new = 0.0;
    const auto ap = problem.A.row(p).transpose();
    const double ap_norm = ws.norms_[p];
    // steps towards satisfying row p
    for (;;) {
      if (++iter > max_iter) {
        res.status = LcpStatus::PivotLimit;
        res.message = "iteration limit reached";
        done = true;
        break;
      }
      ws.d_.noalias() = ws.J_.transpose() * ap;
      const Index free = m - na;
      const double d2 = free > 0 ? ws.d_.tail(free).norm() : 0.0;
      const bool dependent = d2 <= options.dependence_tolerance * ap_norm;
      if (!dependent) ws.dir_.noalias() = ws.J_.rightCols(free) * ws.d_.tail(free);
      // back substitution r = R⁻¹ d₁
      for (Index i = na - 1; i >= 0; --i) {
        double acc = ws.d_[i];
        for (Index j = i + 1; j < na; ++j) acc -= ws.R_(i, j) * ws.r_[j];
        ws.r_[i] = acc / ws.R_(i, i);
      }
      // partial (dual) step length: first active multiplier to reach 0
      double t1 = inf;
      Index k = -1;
      for (Index j = 0; j < na; ++j) {
        if (ws.r_[j] > 0.0 && ws.u_[j] / ws.r_[j] < t1) {
          t1 = ws.u_[j] / ws.r_[j];
          k = j;
        }
      }
      // full step length: row p becomes tight
      const double t2 = dependent ? inf : -ws.s_[p] / (d2 * d2);
      if (t1 == inf && t2 == inf) {
        res.status = LcpStatus::NoSolution;
        res.message = "constraints A x + q >= 0 are infeasible: no solution";
        done = true;
        break;
      }
      const double t = std::min(t1, t2);
      // update the multipliers (and the primal point when the row is independent)
      for (Index j = 0; j < na; ++j) ws.u_[j] -= t * ws.r_[j];
      u_new += t;
      if (!dependent) {
        ws.x_.noalias() += t * ws.dir_;
        ws.as_.noalias() = problem.A * ws.dir_;
        ws.s_.noalias() += t * ws.as_;
      }
      if (t2 <= t1) {
        // add row p: rotate d so only its first na+1 entries are non-zero
        for (Index j = m - 1; j > na; --j) {
          double c, s;
          givens(ws.d_[j - 1], ws.d_[j], c, s);
          ws.d_[j - 1] = c * ws.d_[j - 1] + s * ws.d_[j];
          ws.d_[j] = 0.0;
          rotateColumns(ws.J_, j - 1, j, c, s);
        }
        ws.R_.col(na).head(na + 1) = ws.d_.head(na + 1);
        ws.u_[na] = u_new;
        ws.active_.push_back(static_cast<int>(p));
        ws.is_active_[u(p)] = 1;
        ++na;
        break;
      }
      ws.u_[k] = 0.0;
      drop(k);
    }
  }
  res.pivots = iter;
  ws.previous_.assign(ws.active_.begin(), ws.active_.end());

  // z from the multipliers; x and w recomputed from the data
  res.z.setZero(n);
  for (Index j = 0; j < na; ++j) res.z[ws.active_[u(j)]] = std::max(0.0, ws.u_[j]);
  if (!res.z.allFinite()) {
    res.z.setZero();
    res.status = LcpStatus::NumericalFailure;
    res.message = "non-finite multipliers";
  }
  ws.x_.noalias() = problem.A.transpose() * res.z;
  res.w.noalias() = problem.A * ws.x_;
  res.w += problem.q;
  res.residuals = computeResiduals(problem.q, res.z, res.w);
  if (res.status == LcpStatus::Solved && !isComplementary(res.residuals, options.check_tolerance)) {
    res.status = LcpStatus::NumericalFailure;
    res.message = "active set fails the residual check";
  }
  return res;
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
