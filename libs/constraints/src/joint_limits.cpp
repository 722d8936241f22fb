#include "mannequin/constraints/joint_limits.hpp"

#include <cmath>
#include <stdexcept>

#include "mannequin/math/so3.hpp"

namespace mannequin::constraints {

JointLimits::JointLimits(const skeleton::Model& model, JointLimitOptions options) : options_(options) {
  if (!std::isfinite(options.activation) || options.activation < 0)
    throw std::invalid_argument("joint limits: activation must be finite and >= 0");
  if (options.max_rounds < 0) throw std::invalid_argument("joint limits: max_rounds must be >= 0");
  if (!std::isfinite(options.recovery_speed) || options.recovery_speed < 0)
    throw std::invalid_argument("joint limits: recovery_speed must be finite and >= 0");
  for (const skeleton::Joint& j : model.joints) {
    if (j.type == skeleton::JointType::kFreeFlyer) continue;
    for (int c = 0; c < j.nq; ++c) {
      const int k = j.idx_q + c;
      const double lo = model.lower_limit(k), hi = model.upper_limit(k);
      if (!std::isfinite(lo) && !std::isfinite(hi)) continue;
      Coordinate co;
      co.q = k;
      co.v = j.idx_v;
      co.component = j.type == skeleton::JointType::kBall ? c : -1;
      co.ball_q = j.idx_q;
      co.lower = lo;
      co.upper = hi;
      coordinates_.push_back(co);
    }
  }
  gamma_.resize(model.nv);
  qdot_.resize(model.nv);
  // at most two rows per coordinate: the lists never grow in the loop
  candidates_.reserve(2 * coordinates_.size());
  rows_.reserve(2 * coordinates_.size());
}

int JointLimits::activeCount() const {
  int n = 0;
  for (const LimitRow& r : rows_) n += r.lambda > 0 ? 1 : 0;
  return n;
}

Eigen::RowVector3d JointLimits::ballRow(const Coordinate& c, const Eigen::VectorXd& q) {
  return math::rightJacobianInverseSO3(q.segment<3>(c.ball_q)).row(c.component);  // q̇ = Jr(q)⁻¹ω
}

double JointLimits::rate(const Coordinate& c, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot) {
  return c.component < 0 ? qdot(c.v) : ballRow(c, q).dot(qdot.segment<3>(c.v));
}

lcp::LcpStatus JointLimits::apply(control::Controller& ctl) {
  const Eigen::VectorXd& q = ctl.q();
  const Eigen::VectorXd& qdot_f = ctl.qdotFree();
  const double dt = ctl.config().dt;
  const int nv = static_cast<int>(qdot_f.size());
  rows_.clear();
  // candidates: near or past a limit at q_k + δt q̇_f
  candidates_.clear();
  for (std::size_t i = 0; i < coordinates_.size(); ++i) {
    const Coordinate& c = coordinates_[i];
    const double next = q(c.q) + dt * rate(c, q, qdot_f);
    if (std::isfinite(c.lower) && next < c.lower + options_.activation) candidates_.push_back({static_cast<int>(i), false});
    if (std::isfinite(c.upper) && next > c.upper - options_.activation) candidates_.push_back({static_cast<int>(i), true});
  }
  if (candidates_.empty()) return lcp::LcpStatus::Solved;
  lcp::LcpResult& res = result_;
  // the forces at the candidates move the other coordinates too (through b⁻¹): a coordinate they push
  // past its limit joins the candidates and the LCP is solved again (a few rounds at most)
  for (int round = 0;; ++round) {
    const int n = static_cast<int>(candidates_.size());
    Jc_.setZero(n, nv);
    problem_.q.resize(n);
    for (int r = 0; r < n; ++r) {
      const Coordinate& c = coordinates_[candidates_[r].first];
      const bool upper = candidates_[r].second;
      const double s = upper ? -1.0 : 1.0;
      if (c.component < 0)
        Jc_(r, c.v) = s;
      else
        Jc_.block<1, 3>(r, c.v) = s * ballRow(c, q);
      const double d = upper ? c.upper - q(c.q) : q(c.q) - c.lower;
      problem_.q(r) = Jc_.row(r).dot(qdot_f) + std::max(d / dt, -options_.recovery_speed);
    }
    BinvJcT_ = Jc_.transpose();
    ctl.apparentFrictionLLT().solveInPlace(BinvJcT_);  // b⁻¹ J_cᵀ
    problem_.M.noalias() = Jc_ * BinvJcT_;
    lcp::solveLemke(problem_, workspace_, lcp::LemkeOptions{}, res);
    if (res.status != lcp::LcpStatus::Solved) {
      ++failures_;
      return res.status;
    }
    if (round >= options_.max_rounds) break;
    qdot_ = qdot_f;
    qdot_.noalias() += BinvJcT_ * res.z;
    bool grown = false;
    for (std::size_t i = 0; i < coordinates_.size(); ++i) {
      const Coordinate& c = coordinates_[i];
      const double next = q(c.q) + dt * rate(c, q, qdot_);
      for (const bool upper : {false, true}) {
        const bool past = upper ? std::isfinite(c.upper) && next > c.upper + 1e-9 && next > q(c.q)
                                : std::isfinite(c.lower) && next < c.lower - 1e-9 && next < q(c.q);
        if (!past) continue;
        bool known = false;
        for (const auto& k : candidates_) known = known || (k.first == static_cast<int>(i) && k.second == upper);
        if (!known) {
          candidates_.push_back({static_cast<int>(i), upper});
          grown = true;
        }
      }
    }
    if (!grown) break;
  }
  for (std::size_t r = 0; r < candidates_.size(); ++r) {
    const Coordinate& c = coordinates_[candidates_[r].first];
    const bool upper = candidates_[r].second;
    rows_.push_back({c.q, upper, upper ? c.upper - q(c.q) : q(c.q) - c.lower, res.z(static_cast<Eigen::Index>(r))});
  }
  gamma_.noalias() = Jc_.transpose() * res.z;
  ctl.applyConstraintForce(gamma_);
  return res.status;
}

}  // namespace mannequin::constraints
