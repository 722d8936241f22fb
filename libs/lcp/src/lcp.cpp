#include "mannequin/lcp/lcp.hpp"

#include <algorithm>
#include <cmath>

namespace mannequin::lcp {

const char* statusName(LcpStatus status) {
  switch (status) {
    case LcpStatus::Solved: return "solved";
    case LcpStatus::NoSolution: return "no_solution";
    case LcpStatus::PivotLimit: return "pivot_limit";
    case LcpStatus::Invalid: return "invalid";
    case LcpStatus::NumericalFailure: return "numerical_failure";
  }
  return "invalid";
}

const char* validate(const LcpProblem& problem) { return validate(problem.M, problem.q); }

const char* validate(const MatrixView& M, const VectorView& q) {
  if (M.rows() != M.cols()) return "M is not square";
  if (q.size() != M.rows()) return "q and M sizes differ";
  if (!M.allFinite()) return "M has a NaN or Inf entry";
  if (!q.allFinite()) return "q has a NaN or Inf entry";
  return nullptr;
}

LcpResiduals computeResiduals(const VectorView& q, const VectorView& z, const VectorView& w) {
  LcpResiduals r;
  const Index n = z.size();
  if (n == 0) return r;
  // sign violations
  r.max_neg_w = std::max(0.0, -w.minCoeff());
  r.max_neg_z = std::max(0.0, -z.minCoeff());
  // complementarity and the size of the terms it sums (Mz = w - q)
  double dot = 0.0, scale = 0.0, mz_max = 0.0;
  for (Index i = 0; i < n; ++i) {
    const double mz = w[i] - q[i];
    dot += w[i] * z[i];
    scale += std::abs(z[i]) * (std::abs(q[i]) + std::abs(mz));
    mz_max = std::max(mz_max, std::abs(mz));
  }
  r.complementarity = std::abs(dot);
  r.relative_complementarity = r.complementarity / (1.0 + scale);
  r.relative_sign = std::max(r.max_neg_w, r.max_neg_z) /
                    (1.0 + q.lpNorm<Eigen::Infinity>() + mz_max + z.lpNorm<Eigen::Infinity>());
  return r;
}

}  // namespace mannequin::lcp
