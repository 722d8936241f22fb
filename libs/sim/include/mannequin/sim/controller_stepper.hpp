#pragma once
/// \file controller_stepper.hpp
/// \brief The World's default stepper: one control::Controller (thesis Alg. 2, docs/control.md) per
/// mannequin, its control frames driven by the World's targets.
///
/// Mapping: the World's control frame i is a model frame f_i; it drives the controller's control frame
/// c_i attached to that model frame (the first in the controller config's list), whose pose is
/// oMc = oMf · fMc (fMc the config's offset). So the controller's target is oMd · fMc and its target
/// twist Ad(fMc⁻¹) V_d (body twists). Controller frames that no World frame drives are switched off
/// (setFrameEnabled(false)): with no mocap body their targets would pin them in the room.
///
/// Weight w ∈ [0, 1]: K = w K₀, B = w B₀ (K₀, B₀ from the config, weight applied); w = 0 switches the
/// frame off, so its rows leave the projectors and the posture control takes the limb (2.25).
///
/// The step is the controller's (Alg. 4): computeFreeMotion(); stage 2, the unilateral constraints as
/// rows of a constraints::ConstraintSolver over the producers this stepper owns (the joint limits:
/// constraints::JointLimitRows, revolute bounds and the ball joints' swing ellipse and twist range,
/// Annex D.2) — or, in the World's physics, of the World's shared solver with the contacts, balance and
/// grasps; then integrate(); then the forward kinematics at q_{k+1} (oMi, oMf, com) for data(). A failed
/// solve applies no force and is counted (constraintFailures()); it never throws. dt must equal the
/// controller's δt (the constructor sets the controller's δt to the World's step).
#include <memory>
#include <vector>

#include <optional>

#include "mannequin/constraints/joint_limits.hpp"
#include "mannequin/constraints/solver.hpp"
#include "mannequin/constraints/system.hpp"
#include "mannequin/control/controller.hpp"
#include "mannequin/sim/mannequin_system.hpp"
#include "mannequin/sim/stepper.hpp"

namespace mannequin::sim {

class ControllerStepper final : public Stepper {
 public:
  /// `frames`: model frame indices of the World's control frames; `config.dt` is replaced by `dt`.
  /// \throws std::invalid_argument if a frame has no controller control frame attached to it (naming the
  /// frame and listing the controller's frames), or as control::Controller does (names, gains, q0 size).
  /// `limits`: the joint limits as unilateral constraints (nullopt: none).
  ControllerStepper(const skeleton::Model& model, control::ControllerConfig config, const std::vector<int>& frames,
                    double dt, const skeleton::VectorX& q0,
                    std::optional<constraints::JointLimitOptions> limits = constraints::JointLimitOptions{});
  void setTarget(int i, const math::SE3& oMd, const math::Vector6& V_d, double weight) override;
  void setPosture(const skeleton::VectorX& q_posture) override;
  void reset(const skeleton::VectorX& q) override;
  bool step(double dt) override;
  /// The step in two halves, for the World's physics (the shared constraint solver runs between them):
  /// beginStep = stage 1 (free motion at q_k; the controller's data() holds q_k's kinematics and
  /// Jacobians) and, when `own_constraints`, stage 2 with this stepper's own solver; endStep = stage 3
  /// (integration) and the kinematics at q_{k+1}. step() = beginStep(dt, true) + endStep().
  bool beginStep(double dt, bool own_constraints);
  bool endStep();
  const skeleton::VectorX& q() const override { return controller_->q(); }
  const skeleton::VectorX& qdot() const override { return controller_->qdot(); }
  /// The controller's Data (one per mannequin): poses and CoM at q after each step (Controller::data()).
  const skeleton::Data& data() const override { return controller_->data(); }
  double portEnergy() const override;
  std::string_view kind() const override { return "controller"; }

  /// Gains of the World's control frame i at weight 1 (gain tuning, thesis 4.1.1; the occlusion weight
  /// still scales them); nullptr keeps that one. \throws std::invalid_argument on negative/non-finite gains.
  void setGains(int i, const math::Vector6* stiffness, const math::Vector6* damping);
  /// Constrained mode (thesis 4.1.1): attaches `mechanism` to the World's control frame i and enables it
  /// (its effector starts at the projection of the frame's current pose); nullptr disables the frame's
  /// mechanism. Allocates when attaching (at a mode switch, not every step).
  /// \throws std::invalid_argument as Controller::attachMechanism (bad gains or mechanism).
  void setMechanism(int i, const control::MechanismConfig* mechanism);

  /// The controller (for its energies, wrenches, stability check, mechanisms).
  const control::Controller& controller() const { return *controller_; }
  control::Controller& controller() { return *controller_; }
  /// Controller control frame driven by the World's control frame i.
  int controllerFrame(int i) const { return map_.at(i).index; }
  /// The joint-limit rows of this stepper's own solver (nullptr when off).
  const constraints::JointLimitRows* jointLimits() const { return limits_.get(); }
  /// This stepper's own solver (system 0: the controller), nullptr when it has no producer.
  const constraints::ConstraintSolver* constraintSolver() const { return solver_.get(); }
  /// Own solves that failed (no force applied that step).
  long constraintFailures() const { return failures_; }

 private:
  struct Driven {
    int index = -1;               // controller control frame
    math::SE3 offset;             // fMc
    math::SE3 offset_inv;         // cMf
    math::Vector6 K0, B0;         // gains at weight 1
    double weight = -1.0;         // last weight applied (−1: none yet)
  };
  std::unique_ptr<control::Controller> controller_;
  std::vector<Driven> map_;
  std::unique_ptr<MannequinSystem> system_;
  std::unique_ptr<constraints::JointLimitRows> limits_;
  std::unique_ptr<constraints::ConstraintSolver> solver_;
  long failures_ = 0;
  double dt_;
};

}  // namespace mannequin::sim
