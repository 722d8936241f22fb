#include "mannequin/lcp/pgs.hpp"

#include <algorithm>
#include <cmath>

namespace mannequin::lcp {

void PgsWorkspace::reserve(Index capacity) {
  if (mt_.rows() >= capacity) return;
  mt_.resize(capacity, capacity);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(capacity);
  if (n_ > 0) z.head(n_) = z_.head(n_);
  z_.swap(z);
  inv_diag_.resize(capacity);
}

void PgsWorkspace::resize(Index n) {
  if (n == n_) return;
  reserve(n);
  n_ = n;
  z_.head(n).setZero();
}

namespace {

LcpStatus fail(LcpResult& res, LcpStatus status, const char* message) {
  res.status = status;
  res.message = message;
  res.pivots = 0;
  res.residuals = LcpResiduals{};
  return status;
}

// the sweeps on views, into the first n entries of res.z, res.w
LcpStatus solveViews(const MatrixView& M, const VectorView& q, PgsWorkspace& workspace,
                     const PgsOptions& options, LcpResult& res) {
  if (const char* err = validate(M, q)) return fail(res, LcpStatus::Invalid, err);
  if (!(options.relaxation > 0.0 && options.relaxation < 2.0) || !(options.tolerance >= 0.0) ||
      options.max_iterations < 0) {
    return fail(res, LcpStatus::Invalid, "PGS needs 0 < relaxation < 2, tolerance >= 0, max_iterations >= 0");
  }
  const Index n = q.size();
  if (n > 0 && !(M.diagonal().minCoeff() > 0.0)) {
    return fail(res, LcpStatus::Invalid, "PGS needs a positive diagonal of M");
  }
  const bool warm = options.warm_start && workspace.n_ == n && workspace.z_.head(n).allFinite();
  workspace.resize(n);
  auto z = workspace.z_.head(n);
  if (!warm) z.setZero();
  auto mt = workspace.mt_.topLeftCorner(n, n);
  auto inv_diag = workspace.inv_diag_.head(n);
  auto w = res.w.head(n);
  mt = M.transpose();
  inv_diag = M.diagonal().cwiseInverse();
  const double stop = options.tolerance * (1.0 + q.lpNorm<Eigen::Infinity>());
  const double omega = options.relaxation;

  // sweeps
  res.status = LcpStatus::PivotLimit;
  res.message = "iteration limit reached";
  int sweeps = 0;
  while (sweeps < options.max_iterations) {
    ++sweeps;
    double change = 0.0;
    for (Index i = 0; i < n; ++i) {
      const double wi = mt.col(i).dot(z) + q[i];
      const double zi = std::max(0.0, z[i] - omega * wi * inv_diag[i]);
      change = std::max(change, std::abs(zi - z[i]) / inv_diag[i]);
      z[i] = zi;
    }
    if (!z.allFinite()) {
      z.setZero();
      res.status = LcpStatus::NumericalFailure;
      res.message = "PGS diverged (M not positive semidefinite?)";
      break;
    }
    // converged sweep: accept if the true residuals pass
    if (change <= stop) {
      w.noalias() = M * z;
      w += q;
      if (isComplementary(computeResiduals(q, z, w), options.check_tolerance)) {
        res.status = LcpStatus::Solved;
        res.message = "solved";
        break;
      }
    }
  }
  res.pivots = sweeps;
  res.z.head(n) = z;
  w.noalias() = M * z;
  w += q;
  res.residuals = computeResiduals(q, z, w);
  return res.status;
}

}  // namespace

LcpResult solvePgs(const LcpProblem& problem, PgsWorkspace& workspace, const PgsOptions& options) {
  LcpResult res;
  if (validate(problem) == nullptr) {
    res.z.resize(problem.q.size());
    res.w.resize(problem.q.size());
  }
  solveViews(problem.M, problem.q, workspace, options, res);
  if (res.status == LcpStatus::Invalid) {
    res.z.resize(0);
    res.w.resize(0);
  }
  return res;
}

LcpStatus solvePgs(const MatrixView& M, const VectorView& q, PgsWorkspace& workspace,
                   const PgsOptions& options, LcpResult& result) {
  if (result.z.size() < q.size() || result.w.size() < q.size()) {
    return fail(result, LcpStatus::Invalid, "result.z and result.w need at least n entries (LcpResult::reserve)");
  }
  return solveViews(M, q, workspace, options, result);
}

}  // namespace mannequin::lcp
