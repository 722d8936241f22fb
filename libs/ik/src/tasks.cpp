#include "mannequin/ik/tasks.hpp"

#include <cmath>
#include <stdexcept>

#include "mannequin/math/so3.hpp"

namespace mannequin::ik {

using skeleton::JointType;

void IkContext::fromVelocity(Eigen::Ref<MatrixX> J) const {
  const VectorX& q = *q_;
  for (const auto& joint : model_.joints) {
    if (joint.type != JointType::kBall) continue;
    const Matrix3 Jr = math::rightJacobianSO3(q.segment<3>(joint.idx_q));
    J.middleCols<3>(joint.idx_v) = (J.middleCols<3>(joint.idx_v) * Jr).eval();
  }
}

void Task::limitStep(Eigen::Ref<VectorX>, const StepLimits&) const {}

void Task::setWeight(double w) {
  if (!(w > 0.0) || !std::isfinite(w))
    throw std::invalid_argument("task '" + name_ + "': weight must be finite and > 0, got " + std::to_string(w));
  weight_ = w;
}

unsigned parseAxes(const std::string& axes, const std::string& what) {
  unsigned mask = 0;
  for (char c : axes) {
    const int bit = c == 'x' ? 0 : c == 'y' ? 1 : c == 'z' ? 2 : -1;
    if (bit < 0 || (mask & (1u << bit)))
      throw std::invalid_argument(what + ": axes must be a subset of \"xyz\" without repeats, got \"" + axes + "\"");
    mask |= 1u << bit;
  }
  return mask;
}

namespace {
int popcount3(unsigned m) { return static_cast<int>((m & 1u) + ((m >> 1) & 1u) + ((m >> 2) & 1u)); }

void clampNorm(Eigen::Ref<VectorX> e, double limit) {
  const double n = e.norm();
  if (n > limit && n > 0.0) e *= limit / n;
}
}  // namespace

// ---- FrameTask ---------------------------------------------------------------

FrameTask::FrameTask(const Model& model, const std::string& frame, const std::string& position_axes,
                     const std::string& orientation_axes, const Vector3& point, std::string name)
    : Task(name.empty() ? frame : std::move(name)),
      frame_(model.frameIndex(frame)),
      point_(point),
      pos_mask_(parseAxes(position_axes, "task '" + this->name() + "' position")),
      rot_mask_(parseAxes(orientation_axes, "task '" + this->name() + "' orientation")),
      npos_(popcount3(pos_mask_)),
      nrot_(popcount3(rot_mask_)),
      dim_(npos_ + nrot_),
      target_(SE3::Identity()) {
  if (!point.allFinite()) throw std::invalid_argument("task '" + this->name() + "': non-finite point");
  if (dim_ == 0) throw std::invalid_argument("task '" + this->name() + "': no axis selected");
  J6_.resize(6, model.nv);
}

void FrameTask::setTarget(const SE3& target) {
  if (!target.R.allFinite() || !target.p.allFinite())
    throw std::invalid_argument("task '" + name() + "': non-finite target pose (target kept)");
  if (!math::isRotation(target.R, 1e-6))
    throw std::invalid_argument("task '" + name() + "': target orientation is not a rotation (target kept)");
  target_ = target;
}

void FrameTask::setTargetPosition(const Vector3& p) {
  if (!p.allFinite()) throw std::invalid_argument("task '" + name() + "': non-finite target position (target kept)");
  target_.p = p - target_.R * point_;
}

SE3 FrameTask::current(const IkContext& ctx) const { return ctx.data().oMf[frame_]; }

void FrameTask::evaluate(const IkContext& ctx, Eigen::Ref<MatrixX> J, Eigen::Ref<VectorX> e) const {
  const SE3& oMf = ctx.data().oMf[frame_];
  // LocalWorldAligned: rows (ω world, velocity of the frame origin in world axes)
  skeleton::frameJacobian(ctx.model(), ctx.data(), frame_, skeleton::ReferenceFrame::kLocalWorldAligned, J6_);
  const Vector3 r = oMf.R * point_;  // origin → point, world axes
  const Vector3 w_err = math::logSO3(target_.R * oMf.R.transpose());
  const Vector3 p_err = target_.act(point_) - oMf.act(point_);
  int row = 0;
  for (int a = 0; a < 3; ++a) {
    if (!(rot_mask_ & (1u << a))) continue;
    J.row(row) = J6_.row(a);
    e(row) = w_err(a);
    ++row;
  }
  for (int a = 0; a < 3; ++a) {
    if (!(pos_mask_ & (1u << a))) continue;
    // velocity of the point: v_o + ω × r  →  row a of (v_o − [r]× ω)
    const Vector3 ra = -math::hat(r).row(a).transpose();
    J.row(row) = J6_.row(3 + a) + ra.transpose() * J6_.topRows<3>();
    e(row) = p_err(a);
    ++row;
  }
  ctx.fromVelocity(J);
}

void FrameTask::limitStep(Eigen::Ref<VectorX> e, const StepLimits& limits) const {
  if (nrot_ > 0) clampNorm(e.head(nrot_), limits.angular);
  if (npos_ > 0) clampNorm(e.tail(npos_), limits.linear);
}

// ---- ComTask -----------------------------------------------------------------

ComTask::ComTask(const std::string& axes, std::string name)
    : Task(std::move(name)), mask_(parseAxes(axes, "task 'com'")), dim_(popcount3(mask_)) {
  if (dim_ == 0) throw std::invalid_argument("task '" + this->name() + "': no axis selected");
}

void ComTask::setTarget(const Vector3& c) {
  if (!c.allFinite()) throw std::invalid_argument("task '" + name() + "': non-finite target (target kept)");
  target_ = c;
}

void ComTask::evaluate(const IkContext& ctx, Eigen::Ref<MatrixX> J, Eigen::Ref<VectorX> e) const {
  int row = 0;
  for (int a = 0; a < 3; ++a) {
    if (!(mask_ & (1u << a))) continue;
    J.row(row) = ctx.data().Jcom.row(a);
    e(row) = target_(a) - ctx.data().com(a);
    ++row;
  }
  ctx.fromVelocity(J);
}

void ComTask::limitStep(Eigen::Ref<VectorX> e, const StepLimits& limits) const { clampNorm(e, limits.linear); }

// ---- PostureTask -------------------------------------------------------------

PostureTask::PostureTask(const Model& model, const VectorX& reference, Form form, const VectorX& weights,
                         double beta, std::string name)
    : Task(std::move(name)), form_(form), beta_(beta) {
  const std::string who = "task '" + this->name() + "'";
  if (weights.size() != 0 && weights.size() != model.nv)
    throw std::invalid_argument(who + ": weights have " + std::to_string(weights.size()) + " entries, expected " +
                                std::to_string(model.nv));
  w_ = weights.size() ? weights : VectorX::Ones(model.nv);
  for (int i = 0; i < w_.size(); ++i)
    if (!(w_(i) >= 0.0) || !std::isfinite(w_(i)))
      throw std::invalid_argument(who + ": weight " + std::to_string(i) + " must be finite and >= 0");
  if (!(beta > 0.0 && beta <= 1.0)) throw std::invalid_argument(who + ": beta must be in (0, 1]");
  for (const auto& joint : model.joints) {
    if (joint.type == JointType::kFreeFlyer) continue;
    for (int k = 0; k < joint.nv; ++k)
      if (w_(joint.idx_v + k) > 0.0) coords_.push_back(joint.idx_v + k);
  }
  dim_ = form_ == Form::kJointSpace ? static_cast<int>(coords_.size()) : 1;
  if (dim_ == 0) throw std::invalid_argument(who + ": no coordinate attracted");
  ref_ = VectorX::Zero(model.nq);
  setReference(reference);
}

void PostureTask::setReference(const VectorX& q_ref) {
  if (q_ref.size() != ref_.size())
    throw std::invalid_argument("task '" + name() + "': reference has " + std::to_string(q_ref.size()) +
                                " coordinates, expected " + std::to_string(ref_.size()));
  if (!q_ref.allFinite()) throw std::invalid_argument("task '" + name() + "': non-finite reference (kept)");
  ref_ = q_ref;
}

void PostureTask::evaluate(const IkContext& ctx, Eigen::Ref<MatrixX> J, Eigen::Ref<VectorX> e) const {
  const VectorX& q = ctx.q();
  J.setZero();
  if (form_ == Form::kJointSpace) {
    for (int r = 0; r < dim_; ++r) {
      const int i = coords_[r];  // nq == nv and IK coordinates are q for internal joints
      const double s = std::sqrt(w_(i));
      J(r, i) = s;
      e(r) = s * (ref_(i) - q(i));
    }
  } else {
    double g = 0.0;
    for (int i : coords_) {
      const double d = q(i) - ref_(i);
      g += 0.5 * w_(i) * d * d;
      J(0, i) = w_(i) * d;
    }
    e(0) = -beta_ * g;
  }
}

void PostureTask::limitStep(Eigen::Ref<VectorX> e, const StepLimits& limits) const {
  if (form_ == Form::kJointSpace) clampNorm(e, limits.angular * std::sqrt(static_cast<double>(dim_)));
}

double PostureTask::residual(Eigen::Ref<const VectorX> e) const {
  return form_ == Form::kJointSpace ? e.norm() : std::abs(e(0)) / beta_;
}

}  // namespace mannequin::ik
