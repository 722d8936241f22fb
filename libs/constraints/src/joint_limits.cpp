#include "mannequin/constraints/joint_limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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

lcp::LcpStatus JointLimits::apply(ArticulatedSystem& ctl, double dt) {
  const Eigen::VectorXd& q = ctl.q();
  const Eigen::VectorXd& qdot_f = ctl.qdotFree();
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
    ctl.frictionFactor().solveInPlace(BinvJcT_);  // b⁻¹ J_cᵀ
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
  // refused (a non-finite torque): the free motion stays, and the status says the limits did not act
  if (!ctl.applyConstraintForce(gamma_)) return lcp::LcpStatus::NumericalFailure;
  return res.status;
}

}  // namespace mannequin::constraints

// ---- JointLimitRows: the limits as rows of the shared solver -----------------------------------
namespace mannequin::constraints {

JointLimitRows::JointLimitRows(const ArticulatedSystem& mannequin, int system, JointLimitOptions options)
    : ctl_(&mannequin), system_(system), options_(options) {
  if (!std::isfinite(options.activation) || options.activation < 0)
    throw std::invalid_argument("joint limit rows: activation must be finite and >= 0");
  if (!std::isfinite(options.recovery_speed) || options.recovery_speed < 0)
    throw std::invalid_argument("joint limit rows: recovery_speed must be finite and >= 0");
  if (system < 0) throw std::invalid_argument("joint limit rows: system index must be >= 0");
  const skeleton::Model& model = mannequin.model();
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
  ball_rows_.reserve(3 * balls_.size());
  box_rows_.assign(2 * boxes_.size(), 0);
  ball_has_rows_.assign(balls_.size(), 0);
  ball_R_.assign(balls_.size(), Eigen::Matrix3d::Identity());
  ball_d_.assign(balls_.size(), BallLimitDistances{});
  ball_eval_.assign(balls_.size(), 0);
  // The bounds of farFromLimits(), by sampling the swing directions (720, as BallLimit::maxSwing) with
  // a safety factor. Along a ray u of the ellipse, h(ρu) − 1 = A(ρ − ρ_b)(ρ − ρ₂) with ρ₂ < 0 < ρ_b, so
  // d_s = κ(1 − h) = (ρ_b − ρ)(ρ − ρ₂)/(ρ_b − ρ₂) ≥ m(u)(ρ_b − ρ) on [0, ρ_b], m(u) = −ρ₂/(ρ_b − ρ₂);
  // κ(u) = 1/(A(ρ_b − ρ₂)), and inside the ellipse |dh/ds| = 2|Q(s − c)| ≤ 2/min(a, b).
  for (const int ji : balls_) {
    const skeleton::BallLimit& l = model.joints[static_cast<std::size_t>(ji)].ball_limit;
    constexpr int kSamples = 720;
    const double cx = l.swing_cx / l.swing_a, cy = l.swing_cy / l.swing_b;
    const double C = cx * cx + cy * cy - 1.0;
    BallBound bb;
    bb.rho_min = std::numeric_limits<double>::infinity();
    bb.slope_min = 1.0;
    double kappa_max = 0.0;
    for (int i = 0; i < kSamples; ++i) {
      const double phi = 2.0 * 3.14159265358979323846 * i / kSamples;
      const double ux = std::cos(phi) / l.swing_a, uy = std::sin(phi) / l.swing_b;
      const double A = ux * ux + uy * uy, B = ux * cx + uy * cy;
      const double root = std::sqrt(std::max(0.0, B * B - A * C));
      const double rb = (B + root) / A, r2 = (B - root) / A;
      bb.rho_min = std::min(bb.rho_min, rb);
      bb.slope_min = std::min(bb.slope_min, -r2 / (rb - r2));
      kappa_max = std::max(kappa_max, 1.0 / (A * (rb - r2)));
    }
    bb.rho_min *= 0.98;
    bb.slope_min *= 0.9;
    bb.grad_max = 1.1 * kappa_max * 2.0 / std::min(l.swing_a, l.swing_b);
    bb.twist_min = std::min(-l.twist_lower, l.twist_upper);
    if (!(C < 0.0) || !std::isfinite(bb.rho_min) || !(bb.slope_min > 0.0) || !std::isfinite(bb.grad_max))
      bb.rho_min = -1.0;  // no usable bound: never skip
    ball_bound_.push_back(bb);
  }
}

bool JointLimitRows::farFromLimits(std::size_t bi, double theta, double speed, double dt, double margin) const {
  // θ bounds the rotation angle of R, hence its swing angle θ_s and |θ_t| (R = R_s R_t about t: as
  // quaternions, cos(θ/2) = cos(θ_s/2) cos(θ_t/2)); the rows' rates are bounded by |ds/dω| ≤ f + g
  // (swing_twist.cpp, (61): f, g grow with θ_s) and |dθ_t/dω| ≤ 1 + |Jr| |ds/dω| ≤ 1 + f + g
  const BallBound& b = ball_bound_[bi];
  if (!(theta >= 0.0) || !(theta < b.rho_min) || !(theta < b.twist_min) || !std::isfinite(speed)) return false;
  double g, f;
  if (theta < 1e-3) {
    g = 1.0 + theta * theta / 6.0;
    f = 1.0 / 3.0 + 2.0 * theta * theta / 15.0;
  } else {
    const double s = std::sin(theta), c = std::cos(theta);
    g = theta / s;
    f = (s - theta * c) / (s * s * s);
  }
  const double step = dt * speed;
  return b.slope_min * (b.rho_min - theta) - step * b.grad_max * (f + g) >= margin &&
         b.twist_min - theta - step * (1.0 + f + g) >= margin;
}

int JointLimitRows::activeCount() const {
  int n = 0;
  for (const LimitRow& r : rows_) n += r.lambda > 0 ? 1 : 0;
  return n;
}

bool JointLimitRows::candidate(double dt, double d, int v, int ncols, const double* jac) const {
  const Eigen::VectorXd& qf = ctl_->qdotFree();
  double rate = 0.0;
  for (int c = 0; c < ncols; ++c) rate += jac[c] * qf(v + c);
  return std::min(d, d + dt * rate) < options_.activation;
}

int JointLimitRows::add(int id, RowSet& rows, RowSource source, int coordinate, bool upper, double d, int v,
                        int ncols, const double* jac, double correction) {
  RowInfo info;
  info.kind = RowKind::kUnilateral;
  info.source = source;
  info.producer = id;
  info.tag = coordinate;
  info.distance = d;
  info.recovery_speed = options_.recovery_speed;
  info.system_a = system_;
  info.correction = correction;
  const int r = rows.add(info);
  if (r >= 0) {
    auto J = rows.jacobian(r, system_);
    for (int c = 0; c < ncols; ++c) J(v + c) = jac[c];
  }
  rows_.push_back({coordinate, upper, d, 0.0, source, r});
  return r;
}

void JointLimitRows::addBox(int id, RowSet& rows, std::size_t bi, bool upper, double correction) {
  const Box& b = boxes_[bi];
  const Eigen::VectorXd& q = ctl_->q();
  const double d = upper ? b.upper - q(b.q) : q(b.q) - b.lower;
  Eigen::RowVector3d row(upper ? -1.0 : 1.0, 0.0, 0.0);
  if (b.component >= 0)  // q̇ = Jr(q)⁻¹ω on the ball's three columns
    row = (upper ? -1.0 : 1.0) * math::rightJacobianInverseSO3(q.segment<3>(b.ball_q)).row(b.component);
  add(id, rows, RowSource::kJointLimit, b.q, upper, d, b.v, b.component < 0 ? 1 : 3, row.data(), correction);
  box_rows_[2 * bi + (upper ? 1 : 0)] = 1;
}

void JointLimitRows::addBall(int id, RowSet& rows, std::size_t bi, const BallLimitDistances& d,
                             const double* correction) {
  const int ji = balls_[bi];
  const skeleton::Joint& j = ctl_->model().joints[static_cast<std::size_t>(ji)];
  ball_has_rows_[bi] = 1;
  if (d.singular) {
    const int r = add(id, rows, RowSource::kSwing, j.idx_q, false, d.swing, j.idx_v, 3, d.swing_jacobian.data(),
                      correction ? correction[0] : 0.0);
    ball_rows_.push_back({r, ji, static_cast<int>(bi), 0, true, d.swing, 0.0});
    return;
  }
  const Eigen::RowVector3d neg = -d.twist_jacobian;
  int r = add(id, rows, RowSource::kSwing, j.idx_q, false, d.swing, j.idx_v, 3, d.swing_jacobian.data(),
              correction ? correction[0] : 0.0);
  ball_rows_.push_back({r, ji, static_cast<int>(bi), 0, false, d.swing, d.swing_scale});
  r = add(id, rows, RowSource::kTwist, j.idx_q, false, d.twist_lower, j.idx_v, 3, d.twist_jacobian.data(),
          correction ? correction[1] : 0.0);
  ball_rows_.push_back({r, ji, static_cast<int>(bi), 1, false, d.twist_lower, 0.0});
  r = add(id, rows, RowSource::kTwist, j.idx_q, true, d.twist_upper, j.idx_v, 3, neg.data(),
          correction ? correction[2] : 0.0);
  ball_rows_.push_back({r, ji, static_cast<int>(bi), 2, false, d.twist_upper, 0.0});
}

void JointLimitRows::addRows(int id, double dt, RowSet& rows) {
  const Eigen::VectorXd& q = ctl_->q();
  const skeleton::Model& model = ctl_->model();
  rows_.clear();
  ball_rows_.clear();
  std::fill(box_rows_.begin(), box_rows_.end(), 0);
  std::fill(ball_has_rows_.begin(), ball_has_rows_.end(), 0);
  worst_excess_ = 0.0;
  for (std::size_t bi = 0; bi < boxes_.size(); ++bi) {
    const Box& b = boxes_[bi];
    double lo_d = q(b.q) - b.lower, hi_d = b.upper - q(b.q);
    worst_excess_ = std::max({worst_excess_, std::isfinite(lo_d) ? -lo_d : 0.0, std::isfinite(hi_d) ? -hi_d : 0.0});
    Eigen::RowVector3d row(1.0, 0.0, 0.0);
    if (b.component >= 0) row = math::rightJacobianInverseSO3(q.segment<3>(b.ball_q)).row(b.component);
    const Eigen::RowVector3d neg = -row;
    const int nc = b.component < 0 ? 1 : 3;
    if (std::isfinite(b.lower) && candidate(dt, lo_d, b.v, nc, row.data())) addBox(id, rows, bi, false, 0.0);
    if (std::isfinite(b.upper) && candidate(dt, hi_d, b.v, nc, neg.data())) addBox(id, rows, bi, true, 0.0);
  }
  const Eigen::VectorXd& qf = ctl_->qdotFree();
  for (std::size_t bi = 0; bi < balls_.size(); ++bi) {
    const skeleton::Joint& j = model.joints[static_cast<std::size_t>(balls_[bi])];
    // far inside the cone and the twist range at q_k and after the free step: no candidate, no
    // excess (farFromLimits bounds the rows' distances and rates), so no decomposition
    ball_eval_[bi] = 0;
    if (farFromLimits(bi, q.segment<3>(j.idx_q).norm(), qf.segment<3>(j.idx_v).norm(), dt, options_.activation))
      continue;
    ball_R_[bi] = math::expSO3(q.segment<3>(j.idx_q));
    ball_d_[bi] = ballLimitDistances(j.ball_limit, ball_R_[bi]);
    ball_eval_[bi] = 1;
    const BallLimitDistances& d = ball_d_[bi];
    worst_excess_ = std::max(worst_excess_, d.swing_excess);
    if (!d.singular) worst_excess_ = std::max({worst_excess_, -d.twist_lower, -d.twist_upper});
    // near swing π only the radial swing row (the twist is undefined there); else all three rows
    // when one is a candidate (see the header)
    const Eigen::RowVector3d neg = -d.twist_jacobian;
    if (candidate(dt, d.swing, j.idx_v, 3, d.swing_jacobian.data()) ||
        (!d.singular && (candidate(dt, d.twist_lower, j.idx_v, 3, d.twist_jacobian.data()) ||
                         candidate(dt, d.twist_upper, j.idx_v, 3, neg.data()))))
      addBall(id, rows, bi, d, nullptr);
  }
}

bool JointLimitRows::refine(int id, double dt, RowSet& rows, const std::vector<Eigen::VectorXd>& velocity) {
  if (system_ >= static_cast<int>(velocity.size())) return false;
  constexpr double kTolerance = 1e-9;  // rad: a correction that moved less needs no new solve
  const Eigen::VectorXd& v = velocity[static_cast<std::size_t>(system_)];
  const Eigen::VectorXd& q = ctl_->q();
  const skeleton::Model& model = ctl_->model();
  bool again = false;
  // 1. the rows of the step: their linearisation error at this velocity
  int joint = -1;
  BallLimitDistances next;
  const std::size_t n_ball_rows = ball_rows_.size();
  for (std::size_t k = 0; k < n_ball_rows; ++k) {
    const BallRow& b = ball_rows_[k];
    if (b.row < 0) continue;
    const skeleton::Joint& j = model.joints[static_cast<std::size_t>(b.joint)];
    const skeleton::BallLimit& l = j.ball_limit;
    const Eigen::Vector3d w = v.segment<3>(j.idx_v);
    if (b.joint != joint) {  // where the step takes the ball: R_k exp(δt ω), as the controller integrates
      next = ballLimitDistances(l, ball_R_[static_cast<std::size_t>(b.ball)] * math::expSO3(dt * w), false);
      joint = b.joint;
    }
    double d_next;
    if (b.kind == 0)
      d_next = b.singular ? ellipseRadius(l, next.st.swing_dir) - next.st.swing_angle
                          : b.scale * (1.0 - ellipseLevel(l, next.st.swing));
    else if (next.singular)
      continue;  // the twist is undefined there: the swing row brings the ball back first
    else
      d_next = b.kind == 1 ? next.st.twist - l.twist_lower : l.twist_upper - next.st.twist;
    const double linear = b.d + dt * rows.jacobians(system_).row(b.row).segment<3>(j.idx_v).dot(w);
    const double c = d_next - linear;
    if (!std::isfinite(c)) continue;
    RowInfo& in = rows.info(b.row);
    // the row is at its bound in this answer when the distance it predicts for the end of the step (the
    // LCP's w_r δt) is 0 — whatever λ the answer gives it: an LCP with redundant rows has several
    // answers with the same velocities and different λ (the warm start may pick another), and the
    // decision to solve again must not depend on which
    const double v_rec = std::isfinite(in.recovery_speed) ? std::max(0.0, in.recovery_speed) : 0.0;
    const double w_dt = std::max(b.d, -v_rec * dt) + in.correction + (linear - b.d);
    if ((w_dt <= kTolerance || d_next < 0.0) && std::abs(c - in.correction) > kTolerance) again = true;
    in.correction = c;
  }
  // 2. late rows: limits without a row that this velocity carries past (the forces at the other rows
  // move them too); they join with their correction and the solver assembles again
  for (std::size_t bi = 0; bi < boxes_.size(); ++bi) {
    const Box& b = boxes_[bi];
    const double rate = b.component < 0 ? v(b.v)
                                        : math::rightJacobianInverseSO3(q.segment<3>(b.ball_q)).row(b.component).dot(
                                              v.segment<3>(b.v));
    const double next = q(b.q) + dt * rate;
    if (!box_rows_[2 * bi] && std::isfinite(b.lower) && next < b.lower) addBox(id, rows, bi, false, 0.0);
    if (!box_rows_[2 * bi + 1] && std::isfinite(b.upper) && next > b.upper) addBox(id, rows, bi, true, 0.0);
  }
  for (std::size_t bi = 0; bi < balls_.size(); ++bi) {
    if (ball_has_rows_[bi]) continue;
    const skeleton::Joint& j = model.joints[static_cast<std::size_t>(balls_[bi])];
    const skeleton::BallLimit& l = j.ball_limit;
    const Eigen::Vector3d w = v.segment<3>(j.idx_v);
    // R_k exp(δt ω) turns by at most |q_ball| + δt|ω|: inside the cone and the twist range when that is
    if (farFromLimits(bi, q.segment<3>(j.idx_q).norm() + dt * w.norm(), 0.0, dt, 1e-9)) continue;
    if (!ball_eval_[bi]) {
      ball_R_[bi] = math::expSO3(q.segment<3>(j.idx_q));
      ball_d_[bi] = ballLimitDistances(l, ball_R_[bi]);
      ball_eval_[bi] = 1;
    }
    const BallLimitDistances n1 = ballLimitDistances(l, ball_R_[bi] * math::expSO3(dt * w), false);
    if (n1.swing_excess <= 0.0 && (n1.singular || (n1.twist_lower >= 0.0 && n1.twist_upper >= 0.0))) continue;
    const BallLimitDistances& d = ball_d_[bi];
    double c[3];
    c[0] = (d.singular ? ellipseRadius(l, n1.st.swing_dir) - n1.st.swing_angle
                       : d.swing_scale * (1.0 - ellipseLevel(l, n1.st.swing))) -
           (d.swing + dt * d.swing_jacobian.dot(w));
    const double rate_t = dt * d.twist_jacobian.dot(w);
    c[1] = n1.singular ? 0.0 : (n1.st.twist - l.twist_lower) - (d.twist_lower + rate_t);
    c[2] = n1.singular ? 0.0 : (l.twist_upper - n1.st.twist) - (d.twist_upper - rate_t);
    for (double& x : c) x = std::isfinite(x) ? x : 0.0;
    addBall(id, rows, bi, d, c);
  }
  return again;
}

void JointLimitRows::solved(int /*id*/, const RowSet& rows) {
  for (LimitRow& r : rows_) r.lambda = r.row >= 0 && r.row < rows.size() ? rows.info(r.row).lambda : 0.0;
}

}  // namespace mannequin::constraints
