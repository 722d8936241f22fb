#pragma once
/// \file mannequin_system.hpp
/// \brief A mannequin's controller (control::Controller, stage 2 of its step) as the constrained system the
/// constraint rows act on (constraints::ArticulatedSystem): q_k, q̇_free, b's Cholesky factor and the
/// constraint torque all come from the controller; the joint limits also read its model.
#include "mannequin/constraints/system.hpp"
#include "mannequin/control/controller.hpp"

namespace mannequin::sim {

class MannequinSystem final : public constraints::ArticulatedSystem {
 public:
  explicit MannequinSystem(control::Controller& controller) : ctl_(&controller) {}
  const skeleton::Model& model() const override { return ctl_->model(); }
  const Eigen::VectorXd& q() const override { return ctl_->q(); }
  const Eigen::VectorXd& qdotFree() const override { return ctl_->qdotFree(); }
  const math::TreeCholesky& frictionFactor() const override { return ctl_->apparentFrictionFactor(); }
  bool applyConstraintForce(const Eigen::VectorXd& gamma_c) override {
    return ctl_->applyConstraintForce(gamma_c) == control::ForceStatus::kOk;
  }
  control::Controller& controller() { return *ctl_; }
  const control::Controller& controller() const { return *ctl_; }

 private:
  control::Controller* ctl_;
};

}  // namespace mannequin::sim
