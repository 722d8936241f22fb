#pragma once
/// \file bodies.hpp
/// \brief Where a collision body is and how its points move: what the contact rows need to
/// re-evaluate witness points at q_k (thesis 3.9–3.15).
///
/// A collision body (collision::CollisionWorld body id) is bound to a BodyFrames of one system and a
/// local index in it (a mannequin: the joint index whose frame carries the segment; an object: 0), or
/// to nothing (a static scene body, whose pose is the CollisionWorld's).
#include <Eigen/Dense>

#include "mannequin/math/types.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::constraints {

class BodyFrames {
 public:
  virtual ~BodyFrames() = default;
  /// World pose of body `local` at q_k (the frame the witness points are expressed in).
  virtual const math::SE3& pose(int local) const = 0;
  /// Linear velocity Jacobian (3 × nv of the system) of the material point at world position p of
  /// body `local`: ṗ = J q̇ (world frame). Writes every column (zeros where the body does not move).
  virtual void pointJacobian(int local, const math::Vector3& p, Eigen::Ref<Eigen::Matrix3Xd> J) const = 0;
};

/// A mannequin: body `local` is joint `local`'s frame (skeleton::Data::oMi); the Jacobian uses
/// Data::J (world spatial columns, valid after skeleton::computeJointJacobians at q_k):
/// ṗ = Σ_{k ∈ support(local)} (v_k + ω_k × p) q̇_k.
class MannequinFrames final : public BodyFrames {
 public:
  MannequinFrames(const skeleton::Model& model, const skeleton::Data& data) : model_(&model), data_(&data) {}
  const math::SE3& pose(int joint) const override { return data_->oMi[joint]; }
  void pointJacobian(int joint, const math::Vector3& p, Eigen::Ref<Eigen::Matrix3Xd> J) const override;
  void setData(const skeleton::Data& data) { data_ = &data; }

 private:
  const skeleton::Model* model_;
  const skeleton::Data* data_;
};

}  // namespace mannequin::constraints
