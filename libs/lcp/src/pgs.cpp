#include "mannequin/lcp/pgs.hpp"

#include <algorithm>
#include <cmath>

namespace mannequin::lcp {

void PgsWorkspace::resize(Index n) {
  if (z_.size() == n && mt_.rows() == n) return;
  mt_.resize(n, n);
  z_.setZero(n);
  inv_diag_.resize(n);
}

LcpResult solvePgs(const LcpProblem& problem, PgsWorkspace& workspace, const PgsOptions& options) {
  LcpResult res;
  // input checks
  if (const char* err = validate(problem)) {
    res.status = LcpStatus::Invalid;
    res.message = err;
    return res;
  }
  if (!(options.relaxation > 0.0 && options.relaxation < 2.0) || !(options.tolerance >= 0.0) ||
      options.max_iterations < 0) {
    res.status = LcpStatus::Invalid;
    res.message = "PGS needs 0 < relaxation < 2, tolerance >= 0, max_iterations >= 0";
    return res;
  }
  const Index n = problem.q.size();
  if (n > 0 && !(problem.M.diagonal().minCoeff() > 0.0)) {
    res.status = LcpStatus::Invalid;
    res.message = "PGS needs a positive diagonal of M";
    return res;
  }
  const bool warm = options.warm_start && workspace.z_.size() == n && workspace.z_.allFinite();
  workspace.resize(n);
  if (!warm) workspace.z_.setZero();
  workspace.mt_ = problem.M.transpose();
  workspace.inv_diag_ = problem.M.diagonal().cwiseInverse();
  Eigen::VectorXd& z = workspace.z_;
  const double stop = options.tolerance * (1.0 + problem.q.lpNorm<Eigen::Infinity>());
  const double omega = options.relaxation;

  // sweeps
  res.status = LcpStatus::PivotLimit;
  res.message = "iteration limit reached";
  int sweeps = 0;
  while (sweeps < options.max_iterations) {
    ++sweeps;
    double change = 0.0;
    for (Index i = 0; i < n; ++i) {
      const double wi = workspace.mt_.col(i).dot(z) + problem.q[i];
      const double zi = std::max(0.0, z[i] - omega * wi * workspace.inv_diag_[i]);
      change = std::max(change, std::abs(zi - z[i]) / workspace.inv_diag_[i]);
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
      res.w.noalias() = problem.M * z;
      res.w += problem.q;
      if (isComplementary(computeResiduals(problem.q, z, res.w), options.check_tolerance)) {
        res.status = LcpStatus::Solved;
        res.message = "solved";
        break;
      }
    }
  }
  res.pivots = sweeps;
  res.z = z;
  res.w.noalias() = problem.M * res.z;
  res.w += problem.q;
  res.residuals = computeResiduals(problem.q, res.z, res.w);
  return res;
}

}  // namespace mannequin::lcp
