#include "mannequin/sim/controller_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mannequin::sim {

ControllerStepper::ControllerStepper(const skeleton::Model& model, control::ControllerConfig config,
                                     const std::vector<int>& frames, double dt, const skeleton::VectorX& q0,
                                     std::optional<constraints::JointLimitOptions> limits)
    : dt_(dt) {
  if (!(dt > 0) || !std::isfinite(dt)) throw std::invalid_argument("controller stepper: step must be > 0");
  config.dt = dt;
  controller_ = std::make_unique<control::Controller>(model, config, q0);
  std::vector<bool> used(controller_->numFrames(), false);
  for (int f : frames) {
    if (f < 0 || f >= static_cast<int>(model.frames.size()))
      throw std::invalid_argument("controller stepper: bad model frame index " + std::to_string(f));
    Driven d;
    for (int c = 0; c < controller_->numFrames(); ++c)
      if (!used[c] && controller_->frame(c).frame == f) {
        d.index = c;
        break;
      }
    if (d.index < 0) {
      std::string list;
      for (int c = 0; c < controller_->numFrames(); ++c)
        list += (c ? ", " : "") + controller_->frame(c).name + " (on " + model.frames[controller_->frame(c).frame].name + ")";
      throw std::invalid_argument("controller config " + (config.source.empty() ? std::string("(inline)") : config.source) +
                                  ": no control frame on model frame '" + model.frames[f].name +
                                  "' for the mocap body that drives it (control frames: " + list + ")");
    }
    used[d.index] = true;
    const control::ControlFrameState& s = controller_->frame(d.index);
    d.offset = s.offset;
    d.offset_inv = s.offset.inverse();
    d.K0 = s.stiffness;
    d.B0 = s.damping;
    map_.push_back(d);
  }
  // frames no mocap body drives would pin their segment where it stood: off
  for (int c = 0; c < controller_->numFrames(); ++c)
    if (!used[c]) controller_->setFrameEnabled(c, false);
  if (limits) {
    system_ = std::make_unique<MannequinSystem>(*controller_);
    limits_ = std::make_unique<constraints::JointLimitRows>(*system_, 0, *limits);
    // joint limits only: at most two rows per coordinate (a swing and a twist row per ball joint)
    constraints::SolverOptions so;
    so.max_rows = 2 * model.nv;
    so.max_friction_rows = 1;
    so.max_edges = 1;
    solver_ = std::make_unique<constraints::ConstraintSolver>(std::vector<constraints::ConstrainedSystem*>{system_.get()}, so);
    solver_->addProducer(limits_.get());
  }
}

void ControllerStepper::setTarget(int i, const math::SE3& oMd, const math::Vector6& V_d, double weight) {
  Driven& d = map_.at(i);
  if (!std::isfinite(weight) || !V_d.allFinite() || !oMd.R.allFinite() || !oMd.p.allFinite()) return;
  const double w = std::clamp(weight, 0.0, 1.0);
  if (w != d.weight) {
    controller_->setGains(d.index, w * d.K0, w * d.B0);
    controller_->setFrameEnabled(d.index, w > 0.0);
    d.weight = w;
  }
  // not a rotation: refused, the previous target stays (the controller keeps it)
  (void)controller_->setTarget(d.index, oMd * d.offset, math::actTwist(d.offset_inv, V_d));
}

void ControllerStepper::setGains(int i, const math::Vector6* stiffness, const math::Vector6* damping) {
  Driven& d = map_.at(i);
  const math::Vector6 K = stiffness != nullptr ? *stiffness : d.K0, B = damping != nullptr ? *damping : d.B0;
  const double w = d.weight < 0 ? 1.0 : d.weight;
  controller_->setGains(d.index, w * K, w * B);  // throws on bad gains, before anything changes
  d.K0 = K;
  d.B0 = B;
}

void ControllerStepper::setMechanism(int i, const control::MechanismConfig* mechanism) {
  const Driven& d = map_.at(i);
  if (mechanism == nullptr) {
    if (controller_->frame(d.index).mechanism_enabled) controller_->setMechanismEnabled(d.index, false);
    return;
  }
  controller_->attachMechanism(d.index, *mechanism);
  controller_->setMechanismEnabled(d.index, true);
}

double ControllerStepper::portEnergy() const {
  double e = 0.0;
  for (int c = 0; c < controller_->numFrames(); ++c) e += controller_->frame(c).port.energy;
  return e;
}

void ControllerStepper::setPosture(const skeleton::VectorX& q_posture) { controller_->setPosture(q_posture); }

void ControllerStepper::reset(const skeleton::VectorX& q) {
  controller_->reset(q);
}

bool ControllerStepper::step(double dt) { return beginStep(dt, true) && endStep(); }

bool ControllerStepper::beginStep(double dt, bool own_constraints) {
  if (std::abs(dt - dt_) > 1e-12 * dt_)
    throw std::logic_error("controller stepper: step " + std::to_string(dt) + " s, built for " + std::to_string(dt_) + " s");
  if (controller_->computeFreeMotion() != control::StepStatus::kOk) return false;
  // unilateral constraints (Alg. 4): their force joins q̇ before the integration; a failed solve leaves
  // the step unconstrained (counted in constraintFailures())
  if (own_constraints && solver_ && solver_->solve(dt).solver == constraints::SolverUsed::kFailed) ++failures_;
  return true;
}

bool ControllerStepper::endStep() {
  controller_->integrate();  // also the kinematics and CoM at q_{k+1}, in the controller's Data
  return controller_->q().allFinite();
}

}  // namespace mannequin::sim
