#pragma once
/// \file testing.hpp
/// \brief Deterministic LCP generators shared by the tests, the benchmark and the tool.
/// Header-only; not used by the solvers themselves.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "mannequin/lcp/lcp.hpp"
#include "mannequin/lcp/lemke.hpp"

namespace mannequin::lcp::gen {

/// Uniform random matrix in [lo, hi] (rows×cols), reproducible from seed.
inline Eigen::MatrixXd uniform(Index rows, Index cols, double lo, double hi, std::mt19937& rng) {
  std::uniform_real_distribution<double> dist(lo, hi);
  Eigen::MatrixXd m(rows, cols);
  for (Index j = 0; j < cols; ++j)
    for (Index i = 0; i < rows; ++i) m(i, j) = dist(rng);
  return m;
}

/// Well-conditioned SPD LCP: M = BᵀB/n + I (n×n), q uniform in [−1, 1].
inline LcpProblem makeSpd(Index n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  const Eigen::MatrixXd B = uniform(n, n, -1.0, 1.0, rng);
  LcpProblem p;
  p.M = B.transpose() * B / static_cast<double>(n) + Eigen::MatrixXd::Identity(n, n);
  p.q = uniform(n, 1, -1.0, 1.0, rng);
  return p;
}

/// Symmetric PSD LCP of rank r: M = BBᵀ with B n×r, q uniform in [−1, 1] (may be infeasible).
inline LcpProblem makePsd(Index n, Index r, std::uint32_t seed) {
  std::mt19937 rng(seed);
  const Eigen::MatrixXd B = uniform(n, r, -1.0, 1.0, rng);
  LcpProblem p;
  p.M = B * B.transpose();
  p.q = uniform(n, 1, -1.0, 1.0, rng);
  return p;
}

/// Non-symmetric P-matrix LCP: M = SPD + skew-symmetric (positive definite, hence P).
inline LcpProblem makePMatrix(Index n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  LcpProblem p = makeSpd(n, seed + 1000u);
  const Eigen::MatrixXd S = uniform(n, n, -1.0, 1.0, rng);
  p.M += S - S.transpose();
  return p;
}

/// Strictly copositive (hence copositive-plus), non-symmetric and generally not PSD:
/// entries in [0.1, 1], q uniform in [−1, 1]. Lemke always solves it.
inline LcpProblem makeCopositive(Index n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  LcpProblem p;
  p.M = uniform(n, n, 0.1, 1.0, rng);
  p.q = uniform(n, 1, -1.0, 1.0, rng);
  return p;
}

/// Contact LCP of thesis (3.7): n contact normals on a 42-column (6 root + 36 joint)
/// kinematic tree, b diagonal SPD damping, M = δt J b⁻¹ Jᵀ = A Aᵀ with A = √δt J b^{-1/2}.
struct ContactLike {
  Eigen::MatrixXd J;  ///< n×42 contact Jacobian (rows n_iᵀ J_point)
  Eigen::VectorXd b;  ///< 42, diagonal of the damping matrix
  double dt = 0.01;   ///< time step
  Eigen::MatrixXd A;  ///< n×42, √δt J b^{-1/2}
  LcpProblem lcp;     ///< M = A Aᵀ (+ regularization I), q = d(q_k) + δt J q̇_free
};

/// Builds a contact-like LCP with n rows; most contacts sit on a few end bodies (feet,
/// hands), so rows are highly dependent (rank ≤ 42). About a third of the distances are
/// exactly 0 (touching contacts, degenerate); normals point anywhere (grasp, squeeze).
/// Always feasible since d ≥ 0.
inline ContactLike makeContactLike(Index n, std::uint32_t seed, double regularization = 0.0) {
  constexpr int kJoints = 36;
  constexpr int kCols = 42;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto unit = [&]() {
    Eigen::Vector3d v(gauss(rng), gauss(rng), gauss(rng));
    return Eigen::Vector3d(v.normalized());
  };
  // tree: spine 0-5, head 6-7, two arms 8-14 / 15-21, two legs 22-28 / 29-35
  std::vector<int> parent(kJoints);
  auto chain = [&](int first, int last, int root) {
    for (int j = first; j <= last; ++j) parent[static_cast<std::size_t>(j)] = j == first ? root : j - 1;
  };
  chain(0, 5, -1);
  chain(6, 7, 5);
  chain(8, 14, 5);
  chain(15, 21, 5);
  chain(22, 28, -1);
  chain(29, 35, -1);
  std::vector<Eigen::Vector3d> origin(kJoints), axis(kJoints);
  for (int j = 0; j < kJoints; ++j) {
    const int pj = parent[static_cast<std::size_t>(j)];
    const Eigen::Vector3d base = pj < 0 ? Eigen::Vector3d::Zero() : origin[static_cast<std::size_t>(pj)];
    origin[static_cast<std::size_t>(j)] = base + 0.2 * unit();
    axis[static_cast<std::size_t>(j)] = unit();
  }
  // contact bodies: feet and hands mostly, any body sometimes
  const int ends[] = {35, 28, 21, 14, 35, 28};
  ContactLike c;
  c.J.resize(n, kCols);
  for (Index i = 0; i < n; ++i) {
    const int body = u01(rng) < 0.8 ? ends[static_cast<int>(u01(rng) * 6) % 6]
                                    : static_cast<int>(u01(rng) * kJoints) % kJoints;
    const Eigen::Vector3d p = origin[static_cast<std::size_t>(body)] + 0.05 * unit();
    const Eigen::Vector3d normal = unit();
    Eigen::Matrix<double, 3, kCols> jp = Eigen::Matrix<double, 3, kCols>::Zero();
    jp.block<3, 3>(0, 0).setIdentity();
    // ω × p = −[p]× ω for the root rotation
    jp.block<3, 3>(0, 3) << 0, p.z(), -p.y(), -p.z(), 0, p.x(), p.y(), -p.x(), 0;
    for (int j = body; j >= 0; j = parent[static_cast<std::size_t>(j)]) {
      jp.col(6 + j) = axis[static_cast<std::size_t>(j)].cross(p - origin[static_cast<std::size_t>(j)]);
    }
    c.J.row(i) = normal.transpose() * jp;
  }
  // damping, step, free velocity and distances with a mix of signs and zeros
  c.b.resize(kCols);
  for (int k = 0; k < kCols; ++k) c.b[k] = 0.5 + 4.5 * u01(rng);
  Eigen::VectorXd qdot_free(kCols);
  for (int k = 0; k < kCols; ++k) qdot_free[k] = 2.0 * u01(rng) - 1.0;
  // distances d(q_k) ≥ 0 (a third exactly 0): x = −√δt b^{1/2} q̇_free gives A x + q = d ≥ 0,
  // so the LCP is feasible whatever the normals
  Eigen::VectorXd d(n);
  for (Index i = 0; i < n; ++i) d[i] = u01(rng) < 0.33 ? 0.0 : 0.01 * u01(rng);
  c.A = std::sqrt(c.dt) * c.J * c.b.cwiseInverse().cwiseSqrt().asDiagonal();
  c.lcp.M = c.A * c.A.transpose();
  if (regularization > 0.0) c.lcp.M.diagonal().array() += regularization;
  c.lcp.q = d + c.dt * c.J * qdot_free;
  return c;
}

}  // namespace mannequin::lcp::gen

namespace mannequin::lcp {

/// A dense M (kept by reference) as an LcpMatrixOperator, for the operator entries of Lemke in tests.
class DenseOperator final : public LcpMatrixOperator {
 public:
  explicit DenseOperator(const Eigen::MatrixXd& M) : M_(M) {}
  Index size() const override { return M_.rows(); }
  void column(Index j, Eigen::Ref<Eigen::VectorXd> out) const override { out = M_.col(j); }
  void multiply(const VectorView& z, Eigen::Ref<Eigen::VectorXd> out) const override { out.noalias() = M_ * z; }
  double maxAbs() const override { return M_.size() > 0 ? M_.cwiseAbs().maxCoeff() : 0.0; }

 private:
  const Eigen::MatrixXd& M_;
};

}  // namespace mannequin::lcp
