#pragma once
/// \file system.hpp
/// \brief A system the constraint rows act on: first-order dynamics b q̇ = Γ (thesis 2.4), split in
/// the three stages of Alg. 4 — free motion, constraint forces, integration.
///
/// The solver only needs, at q_k after the free motion: nv, q̇_free, the action of b⁻¹ on columns
/// (b's Cholesky factor, along the tree of coordinates), and a way to add a constraint torque (q̇ = q̇_free + b⁻¹Γ_c). Implementations:
/// MannequinSystem (a control::Controller, below) and sim's rigid objects.
#include <Eigen/Dense>

#include "mannequin/control/controller.hpp"
#include "mannequin/math/tree_cholesky.hpp"

namespace mannequin::constraints {

class ConstrainedSystem {
 public:
  virtual ~ConstrainedSystem() = default;
  virtual int nv() const = 0;
  /// q̇_free (nv) of the current step (after the free-motion stage).
  virtual const Eigen::VectorXd& qdotFree() const = 0;
  /// b's Cholesky factor (b = Lᵀ L along the system's tree of coordinates, math::TreeCholesky) of
  /// the current step.
  virtual const math::TreeCholesky& frictionFactor() const = 0;
  /// Adds b⁻¹Γ_c to q̇ (Γ_c: nv, generalised force of the constraints). Never throws in the loop: returns
  /// false when the system refuses it (a non-finite Γ_c, no free motion this step), q̇ unchanged.
  virtual bool applyConstraintForce(const Eigen::VectorXd& gamma_c) = 0;
};

/// A mannequin's controller as a constrained system (stage 2 of control::Controller).
class MannequinSystem final : public ConstrainedSystem {
 public:
  explicit MannequinSystem(control::Controller& controller) : ctl_(&controller) {}
  int nv() const override { return ctl_->model().nv; }
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

}  // namespace mannequin::constraints
