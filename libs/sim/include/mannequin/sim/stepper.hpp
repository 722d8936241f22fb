#pragma once
/// \file stepper.hpp
/// \brief What the World steps for one mannequin: control frames pulled towards world targets, one
/// fixed step at a time. Two implementations:
/// - ControllerStepper (controller_stepper.hpp): the control library's Controller, the thesis's
///   first-order dynamics with spring-damper couplings, priorities, posture control and gravity
///   (the default; the unilateral constraint solver slots in between its stages later);
/// - KinematicTracker (tracker.hpp): damped least squares on the task errors, purely kinematic, with
///   joint limits clamped (a reference and a fallback: `stepper: kinematic` in the sim config).
///
/// Conventions shared by both: control frame i is a MODEL frame (skeleton::Model::frames); its target
/// oMd is a world pose; its target twist V_d is the target's BODY twist ((ω, v) in target axes, v the
/// velocity of the target origin: V_d = (Rᵀω_w, Rᵀṗ_w)); its weight w ∈ [0, 1] scales its coupling
/// (0 hands the frame to the posture control, as the occlusion policy does).
#include <string_view>

#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::sim {

class Stepper {
 public:
  virtual ~Stepper() = default;
  /// Target pose (world), target body twist and weight of control frame i. Never throws in the loop:
  /// a non-finite target is ignored (the previous one is kept).
  virtual void setTarget(int i, const math::SE3& oMd, const math::Vector6& V_d, double weight) = 0;
  /// Posture target q_d (nq) of the posture control. \throws std::invalid_argument on size/NaN.
  virtual void setPosture(const skeleton::VectorX& q_posture) = 0;
  /// State q, q̇ = 0, targets at the current control-frame poses. \throws on size/NaN.
  virtual void reset(const skeleton::VectorX& q) = 0;
  /// One step of length dt (the World's fixed step). Returns false (state unchanged) if it produced
  /// non-finite numbers.
  virtual bool step(double dt) = 0;
  virtual const skeleton::VectorX& q() const = 0;
  virtual const skeleton::VectorX& qdot() const = 0;
  /// Kinematics at the current q (after reset/step): oMi, oMf, com.
  virtual const skeleton::Data& data() const = 0;
  /// Energy delivered at the control ports since reset (J): Σ_i ∫ W_iᵀV_i dt of the target couplings
  /// (thesis 2.3; passivity keeps it bounded below); NaN when the stepper has no forces (kinematic).
  virtual double portEnergy() const = 0;
  /// "controller" or "kinematic" (logs, sim.world).
  virtual std::string_view kind() const = 0;
};

}  // namespace mannequin::sim
