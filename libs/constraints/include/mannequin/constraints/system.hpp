#pragma once
/// \file system.hpp
/// \brief A system the constraint rows act on: first-order dynamics b q̇ = Γ (thesis 2.4), split in
/// the three stages of Alg. 4 — free motion, constraint forces, integration.
///
/// The solver only needs, at q_k after the free motion: nv, q̇_free, the action of b⁻¹ on columns
/// (b's Cholesky factor, along the tree of coordinates), and a way to add a constraint torque
/// (q̇ = q̇_free + b⁻¹Γ_c). An ArticulatedSystem also gives its skeleton model and q_k (the joint limits
/// read them). Implementations: sim::MannequinSystem (a mannequin's control::Controller) and sim's rigid
/// objects; this library does not depend on the controller.
#include <Eigen/Dense>

#include "mannequin/math/tree_cholesky.hpp"
#include "mannequin/skeleton/model.hpp"

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

/// A constrained system with a skeleton: its model and its configuration q_k of the current step.
class ArticulatedSystem : public ConstrainedSystem {
 public:
  virtual const skeleton::Model& model() const = 0;
  /// q_k (nq), the configuration the free motion was computed at.
  virtual const Eigen::VectorXd& q() const = 0;
  int nv() const override { return model().nv; }
};

}  // namespace mannequin::constraints
