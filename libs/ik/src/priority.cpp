#include "mannequin/ik/priority.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/SVD>

#include "mannequin/core/check.hpp"

namespace mannequin::ik {

namespace {

// Solves with the thin SVD of Aᵀ = U Σ Vᵀ (so A = V Σ Uᵀ): out = U f(Σ) Vᵀ r with f(σ) =
// σ/(σ²+λ²) above the rank threshold, 0 below. Returns the rank; U_r is left in `svd`.
int applyInverse(const Eigen::JacobiSVD<MatrixX>& svd, const VectorX& r, double lambda, double tol,
                 VectorX& w, VectorX& out) {
  const auto& s = svd.singularValues();
  const int m = static_cast<int>(s.size());
  w.noalias() = svd.matrixV().transpose() * r;
  int rank = 0;
  for (int i = 0; i < m; ++i) {
    if (s(i) > tol) {
      ++rank;
      w(i) *= s(i) / (s(i) * s(i) + lambda * lambda);
    } else {
      w(i) = 0.0;
    }
  }
  out.noalias() = svd.matrixU() * w;
  return rank;
}

}  // namespace

PriorityLoop::PriorityLoop(int n, PriorityOptions options) : n_(n), options_(options) {
  if (n <= 0) throw std::invalid_argument("PriorityLoop: size must be > 0, got " + std::to_string(n));
  if (!(options.rank_tolerance >= 0.0) || !std::isfinite(options.rank_tolerance))
    throw std::invalid_argument("PriorityLoop: rank_tolerance must be finite and >= 0");
  if (!(options.max_step > 0.0)) throw std::invalid_argument("PriorityLoop: max_step must be > 0");
  dtheta_ = VectorX::Zero(n);
  P_ = MatrixX::Identity(n, n);
  P0_ = MatrixX::Identity(n, n);
}

const VectorX& PriorityLoop::solve(const std::vector<LinearLevel>& levels, const VectorX* free,
                                   const VectorX* dtheta0, const std::vector<LevelClamp>* clamps) {
  const double tol = options_.rank_tolerance;
  int total_rows = 0;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const auto& L = levels[k];
    const std::string where = "priority level " + std::to_string(k + 1);
    if (L.J.cols() != n_)
      throw std::invalid_argument(where + ": Jacobian has " + std::to_string(L.J.cols()) + " columns, expected " +
                                  std::to_string(n_));
    if (L.dx.size() != L.J.rows())
      throw std::invalid_argument(where + ": Δx has " + std::to_string(L.dx.size()) + " rows, Jacobian " +
                                  std::to_string(L.J.rows()));
    if (!(L.damping >= 0.0) || !std::isfinite(L.damping))
      throw std::invalid_argument(where + ": damping must be finite and >= 0");
    if (!L.J.allFinite() || !L.dx.allFinite()) throw std::invalid_argument(where + ": non-finite Jacobian or Δx");
    total_rows += static_cast<int>(L.J.rows());
  }
  if (free) MANNEQUIN_CHECK_ARGUMENT_SIZE(free->size(), n_, "free mask");
  if (dtheta0) MANNEQUIN_CHECK_ARGUMENT_SIZE(dtheta0->size(), n_, "Δθ_0");
  const int p = static_cast<int>(levels.size());
  int clamp_rows = 0;
  if (clamps)
    for (const auto& c : *clamps) {
      if (c.coordinate < 0 || c.coordinate >= n_ || c.level < 1 || c.level >= p || !std::isfinite(c.dtheta))
        throw std::invalid_argument("PriorityLoop: clamp of coordinate " + std::to_string(c.coordinate) +
                                    " at level " + std::to_string(c.level + 1) + " is out of range (" +
                                    std::to_string(n_) + " coordinates, levels 2.." + std::to_string(p) +
                                    ") or not finite");
      ++clamp_rows;
    }
  total_rows += clamp_rows;

  if (dtheta0) dtheta_ = *dtheta0;
  else dtheta_.setZero(n_);
  P_.setZero(n_, n_);
  if (free) P_.diagonal() = *free;
  else P_.diagonal().setOnes();
  const bool full = options_.update == ProjectorUpdate::kFull;
  if (full) {
    P0_ = P_;
    JA_.resize(total_rows, n_);
  }
  ranks_.assign(levels.size(), 0);
  C_.setZero(n_, static_cast<Eigen::Index>(levels.size()));

  int rows = 0;
  VectorX step(n_);
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const auto& L = levels[k];
    const int m = static_cast<int>(L.J.rows());
    if (clamps) {
      // coordinates held from this level on: rows e_iᵀΔθ = target, strictly above level k
      int c = 0;
      for (const auto& cl : *clamps) c += cl.level == static_cast<int>(k);
      if (c > 0) {
        E_.setZero(c, n_);
        rE_.resize(c);
        int row = 0;
        for (const auto& cl : *clamps) {
          if (cl.level != static_cast<int>(k)) continue;
          E_(row, cl.coordinate) = 1.0;
          rE_(row) = cl.dtheta - dtheta_(cl.coordinate);
          ++row;
        }
        Jhat_.noalias() = E_ * P_;
        Eigen::JacobiSVD<MatrixX> svd(Jhat_.transpose(), Eigen::ComputeThinU | Eigen::ComputeThinV);
        const int r = applyInverse(svd, rE_, 0.0, tol, w_, step);
        dtheta_ += step;
        C_.col(static_cast<Eigen::Index>(k)) += step;
        if (!full) {
          if (r > 0) P_.noalias() -= svd.matrixU().leftCols(r) * svd.matrixU().leftCols(r).transpose();
        } else {
          JA_.middleRows(rows, c) = E_;
          rows += c;
          fullProjector(rows);
        }
      }
    }
    if (m == 0) continue;
    Jhat_.noalias() = L.J * P_;
    r_ = L.dx;
    r_.noalias() -= L.J * dtheta_;
    const bool last = k + 1 == levels.size();
    if (last && L.damping > 0.0) {
      // No projector is needed after the last level: Ĵ^{+λ} r = Ĵᵀ(ĴĴᵀ + λ²I)⁻¹ r by Cholesky
      // (or (ĴᵀĴ + λ²I)⁻¹Ĵᵀ r when m > n), much cheaper than an SVD for a tall posture level.
      const double l2 = L.damping * L.damping;
      if (m <= n_) {
        MatrixX G = Jhat_ * Jhat_.transpose();
        G.diagonal().array() += l2;
        step.noalias() = Jhat_.transpose() * G.llt().solve(r_);
      } else {
        MatrixX G = Jhat_.transpose() * Jhat_;
        G.diagonal().array() += l2;
        step = G.llt().solve(Jhat_.transpose() * r_);
      }
      ranks_[k] = -1;  // not computed
      const double smax = step.lpNorm<Eigen::Infinity>();
      if (smax > options_.max_step) step *= options_.max_step / smax;
      dtheta_ += step;
      C_.col(static_cast<Eigen::Index>(k)) += step;
      continue;
    }
    Eigen::JacobiSVD<MatrixX> svd(Jhat_.transpose(), Eigen::ComputeThinU | Eigen::ComputeThinV);
    ranks_[k] = applyInverse(svd, r_, L.damping, tol, w_, step);
    const double smax = step.lpNorm<Eigen::Infinity>();
    if (smax > options_.max_step) step *= options_.max_step / smax;
    dtheta_ += step;
    C_.col(static_cast<Eigen::Index>(k)) += step;
    if (!full) {
      // (8): P_k = P_{k−1} − Ĵ^+Ĵ, and Ĵ^+Ĵ = U_r U_rᵀ (row space of Ĵ)
      const int r = ranks_[k];
      if (r > 0) P_.noalias() -= svd.matrixU().leftCols(r) * svd.matrixU().leftCols(r).transpose();
    } else {
      // (7): P_k = P_0 − (J^A P_0)^+ (J^A P_0), recomputed from the augmented Jacobian
      JA_.middleRows(rows, m) = L.J;
      rows += m;
      fullProjector(rows);
    }
  }
  return dtheta_;
}

void PriorityLoop::fullProjector(int rows) {
  JAhat_.noalias() = JA_.topRows(rows) * P0_;
  Eigen::JacobiSVD<MatrixX> svdA(JAhat_.transpose(), Eigen::ComputeThinU);
  const auto& s = svdA.singularValues();
  int r = 0;
  while (r < s.size() && s(r) > options_.rank_tolerance) ++r;
  P_ = P0_;
  if (r > 0) P_.noalias() -= svdA.matrixU().leftCols(r) * svdA.matrixU().leftCols(r).transpose();
}

MatrixX dampedInverse(const MatrixX& J, double lambda, double rank_tolerance) {
  Eigen::JacobiSVD<MatrixX> svd(J.transpose(), Eigen::ComputeThinU | Eigen::ComputeThinV);
  const auto& s = svd.singularValues();
  VectorX f = VectorX::Zero(s.size());
  for (int i = 0; i < s.size(); ++i)
    if (s(i) > rank_tolerance) f(i) = s(i) / (s(i) * s(i) + lambda * lambda);
  return svd.matrixU() * f.asDiagonal() * svd.matrixV().transpose();
}

}  // namespace mannequin::ik
