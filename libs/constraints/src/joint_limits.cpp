#include "mannequin/constraints/joint_limits.hpp"

#include <algorithm>
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

// ---- JointLimitRows: the limits as rows of the shared solver -----------------------------------
namespace mannequin::constraints {

JointLimitRows::JointLimitRows(const control::Controller& controller, int system, JointLimitOptions options)
    : ctl_(&controller), system_(system), options_(options) {
  if (!std::isfinite(options.activation) || options.activation < 0)
    throw std::invalid_argument("joint limit rows: activation must be finite and >= 0");
  if (!std::isfinite(options.recovery_speed) || options.recovery_speed < 0)
    throw std::invalid_argument("joint limit rows: recovery_speed must be finite and >= 0");
  if (system < 0) throw std::invalid_argument("joint limit rows: system index must be >= 0");
  const skeleton::Model& model = controller.model();
  for (int ji = 0; ji < static_cast<int>(model.joints.size()); ++ji) {
    const skeleton::Joint& j = model.joints[ji];
    if (j.type == skeleton::JointType::kFreeFlyer) continue;
    if (j.type == skeleton::JointType::kBall && j.ball_limit.enabled) {
      balls_.push_back(ji);
      continue;
    }
    for (int c = 0; c < j.nq; ++c) {
      const int k = j.idx_q + c;
      const double lo = model.lower_limit(k), hi = model.upper_limit(k);
      if (!std::isfinite(lo) && !std::isfinite(hi)) continue;
      boxes_.push_back({k, j.idx_v + (j.type == skeleton::JointType::kBall ? 0 : c),
                        j.type == skeleton::JointType::kBall ? c : -1, j.idx_q, lo, hi});
    }
  }
  rows_.reserve(2 * boxes_.size() + 3 * balls_.size());
}

int JointLimitRows::activeCount() const {
  int n = 0;
  for (const LimitRow& r : rows_) n += r.lambda > 0 ? 1 : 0;
  return n;
}

void JointLimitRows::add(int id, double dt, RowSet& rows, RowSource source, int coordinate, bool upper,
                         double d, int v, int ncols, const double* jac) {
  const Eigen::VectorXd& qf = ctl_->qdotFree();
  double rate = 0.0;
  for (int c = 0; c < ncols; ++c) rate += jac[c] * qf(v + c);
  if (std::min(d, d + dt * rate) >= options_.activation) return;
  RowInfo info;
  info.kind = RowKind::kUnilateral;
  info.source = source;
  info.producer = id;
  info.tag = coordinate;
  info.distance = d;
  info.recovery_speed = options_.recovery_speed;
  info.system_a = system_;
  const int r = rows.add(info);
  if (r >= 0) {
    auto J = rows.jacobian(r, system_);
    for (int c = 0; c < ncols; ++c) J(v + c) = jac[c];
  }
  rows_.push_back({coordinate, upper, d, 0.0, source, r});
}

void JointLimitRows::addRows(int id, double dt, RowSet& rows) {
  const Eigen::VectorXd& q = ctl_->q();
  const skeleton::Model& model = ctl_->model();
  rows_.clear();
  worst_excess_ = 0.0;
  for (const Box& b : boxes_) {
    double lo_d = q(b.q) - b.lower, hi_d = b.upper - q(b.q);
    worst_excess_ = std::max({worst_excess_, std::isfinite(lo_d) ? -lo_d : 0.0, std::isfinite(hi_d) ? -hi_d : 0.0});
    if (b.component < 0) {
      const double plus = 1.0, minus = -1.0;
      if (std::isfinite(b.lower)) add(id, dt, rows, RowSource::kJointLimit, b.q, false, lo_d, b.v, 1, &plus);
      if (std::isfinite(b.upper)) add(id, dt, rows, RowSource::kJointLimit, b.q, true, hi_d, b.v, 1, &minus);
    } else {
      // q̇ = Jr(q)⁻¹ω on the ball's three columns
      const Eigen::RowVector3d row = math::rightJacobianInverseSO3(q.segment<3>(b.ball_q)).row(b.component);
      const Eigen::RowVector3d neg = -row;
      if (std::isfinite(b.lower)) add(id, dt, rows, RowSource::kJointLimit, b.q, false, lo_d, b.v, 3, row.data());
      if (std::isfinite(b.upper)) add(id, dt, rows, RowSource::kJointLimit, b.q, true, hi_d, b.v, 3, neg.data());
    }
  }
  for (int ji : balls_) {
    const skeleton::Joint& j = model.joints[ji];
    const BallLimitDistances d = ballLimitDistances(j.ball_limit, math::expSO3(q.segment<3>(j.idx_q)));
    worst_excess_ = std::max(worst_excess_, d.swing_excess);
    add(id, dt, rows, RowSource::kSwing, j.idx_q, false, d.swing, j.idx_v, 3, d.swing_jacobian.data());
    if (d.singular) continue;  // the twist is undefined near swing π: the swing row brings it back first
    worst_excess_ = std::max({worst_excess_, -d.twist_lower, -d.twist_upper});
    const Eigen::RowVector3d neg = -d.twist_jacobian;
    add(id, dt, rows, RowSource::kTwist, j.idx_q, false, d.twist_lower, j.idx_v, 3, d.twist_jacobian.data());
    add(id, dt, rows, RowSource::kTwist, j.idx_q, true, d.twist_upper, j.idx_v, 3, neg.data());
  }
}

void JointLimitRows::solved(int /*id*/, const RowSet& rows) {
  for (LimitRow& r : rows_) r.lambda = r.row >= 0 && r.row < rows.size() ? rows.info(r.row).lambda : 0.0;
}

}  // namespace mannequin::constraints
