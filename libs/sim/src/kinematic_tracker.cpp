#include "mannequin/sim/tracker.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "mannequin/core/check.hpp"
#include "mannequin/math/pinv.hpp"

namespace mannequin::sim {

KinematicTracker::KinematicTracker(const skeleton::Model& model, std::vector<int> frames, const TrackerGains& gains,
                                   const skeleton::VectorX& q0)
    : model_(model), frames_(std::move(frames)), gains_(gains), data_(model) {
  for (int f : frames_)
    if (f < 0 || f >= static_cast<int>(model.frames.size())) throw std::invalid_argument("tracker: bad frame index");
  targets_.resize(frames_.size());
  weights_.assign(frames_.size(), 0.0);
  Ji_.resize(6, model.nv);
  J_.resize(6 * frames_.size(), model.nv);
  e_.resize(6 * frames_.size());
  q_posture_ = q0;
  reset(q0);
}

void KinematicTracker::setPosture(const skeleton::VectorX& q_posture) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q_posture.size(), model_.nq, "posture q_posture");
  if (!q_posture.allFinite()) throw std::invalid_argument("tracker: posture with non-finite values");
  q_posture_ = q_posture;
}

void KinematicTracker::reset(const skeleton::VectorX& q) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q.size(), model_.nq, "configuration q");
  if (!q.allFinite()) throw std::invalid_argument("tracker: configuration with non-finite values");
  q_ = q;
  qdot_ = skeleton::VectorX::Zero(model_.nv);
  skeleton::forwardKinematics(model_, data_, q_);
  skeleton::computeJointJacobians(model_, data_);
  skeleton::centerOfMass(model_, data_);
  for (std::size_t i = 0; i < frames_.size(); ++i) targets_[i] = data_.oMf[frames_[i]];
}

void KinematicTracker::setTarget(int i, const math::SE3& oMd, double weight) {
  if (!oMd.R.allFinite() || !oMd.p.allFinite() || !std::isfinite(weight)) return;  // keep the previous target
  targets_.at(i) = oMd;
  weights_.at(i) = weight;
}

bool KinematicTracker::step(double dt) {
  // data_ holds the kinematics at q_ (from reset or the previous step)
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    const double w = weights_[i];
    skeleton::frameJacobian(model_, data_, frames_[i], skeleton::ReferenceFrame::kLocal, Ji_);
    J_.middleRows(6 * i, 6) = w * Ji_;
    e_.segment<6>(6 * i) = w * gains_.task * math::logSE3(data_.oMf[frames_[i]].inverse() * targets_[i]);
  }
  const math::MatrixX Jp = math::dampedPseudoInverse(J_, gains_.damping);
  skeleton::VectorX posture = gains_.posture * skeleton::difference(model_, q_, q_posture_);
  // the root is placed by the tasks only: a posture pull on it would leak through the damped projector
  for (const skeleton::Joint& j : model_.joints)
    if (j.type == skeleton::JointType::kFreeFlyer) posture.segment(j.idx_v, j.nv).setZero();
  skeleton::VectorX v = Jp * e_ + posture - Jp * (J_ * posture);
  const double m = v.cwiseAbs().maxCoeff();
  if (m > gains_.max_speed) v *= gains_.max_speed / m;
  if (!v.allFinite()) return false;
  skeleton::VectorX q = skeleton::clampToLimits(model_, skeleton::integrate(model_, q_, v, dt));
  if (!q.allFinite()) return false;
  qdot_ = skeleton::difference(model_, q_, q) / dt;
  q_ = q;
  skeleton::forwardKinematics(model_, data_, q_);
  skeleton::computeJointJacobians(model_, data_);
  skeleton::centerOfMass(model_, data_);
  return true;
}

}  // namespace mannequin::sim
