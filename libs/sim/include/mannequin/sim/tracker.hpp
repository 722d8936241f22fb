#pragma once
/// \file tracker.hpp
/// \brief The per-mannequin stepper the World drives: control frames pulled towards their targets,
/// posture control in the remaining freedom, one fixed step at a time.
///
/// KinematicTracker (first-order, kinematic; `stepper: kinematic`, and the calibration fit): each step, with e_i = log(oMf_i⁻¹ oMd_i) the error of control frame i in
/// its own axes ((ω, v) order) and J_i its body Jacobian (skeleton::frameJacobian, kLocal),
///   q̇ = J_w⁺ (w ∘ k_task e) + (I − J_w⁺ J_w) k_post (q_post ⊖ q),   J_w = [w_i J_i]
/// with J_w⁺ the damped pseudo-inverse (math::dampedPseudoInverse, λ = damping), q̇ clamped to
/// max_speed, then q ← clampToLimits(q ⊕ q̇ δt) (skeleton::integrate). The posture term leaves the
/// free-flyer root alone (its components are zero): the tasks place the mannequin in the room. w_i ∈ [0, 1] is the task
/// weight (occlusion blends it to 0, handing the frame to the posture control). The target twist is
/// not used (no feed-forward): the tracker lags a moving target by |V|/k_task.
#include <limits>
#include <string>
#include <vector>

#include "mannequin/sim/stepper.hpp"

namespace mannequin::sim {

struct TrackerGains {
  double task = 40.0;       ///< k_task (1/s): error decays as exp(−k t) for a reachable target
  double posture = 2.0;     ///< k_post (1/s)
  double damping = 0.05;    ///< λ of the damped pseudo-inverse
  double max_speed = 20.0;  ///< |q̇_k| bound (rad/s, m/s)
};

class KinematicTracker final : public Stepper {
 public:
  /// `frames`: model frame indices of the control frames. \throws std::invalid_argument on a bad index.
  KinematicTracker(const skeleton::Model& model, std::vector<int> frames, const TrackerGains& gains,
                   const skeleton::VectorX& q0);
  /// Target pose (world) and weight of control frame i.
  void setTarget(int i, const math::SE3& oMd, double weight);
  void setTarget(int i, const math::SE3& oMd, const math::Vector6& /*V_d*/, double weight) override {
    setTarget(i, oMd, weight);
  }
  void setPosture(const skeleton::VectorX& q_posture) override;
  void reset(const skeleton::VectorX& q) override;
  /// One step of length dt. Returns false (state unchanged) if the step produced non-finite numbers.
  bool step(double dt) override;
  const skeleton::VectorX& q() const override { return q_; }
  const skeleton::VectorX& qdot() const override { return qdot_; }
  /// Kinematics at the current q (after reset/step): oMi, oMf, J, com.
  const skeleton::Data& data() const override { return data_; }
  double portEnergy() const override { return std::numeric_limits<double>::quiet_NaN(); }
  std::string_view kind() const override { return "kinematic"; }
  const math::SE3& target(int i) const { return targets_[i]; }
  double weight(int i) const { return weights_[i]; }

 private:
  const skeleton::Model& model_;
  std::vector<int> frames_;
  TrackerGains gains_;
  skeleton::Data data_;
  skeleton::VectorX q_, qdot_, q_posture_;
  std::vector<math::SE3> targets_;
  std::vector<double> weights_;
  math::Matrix6X Ji_;
  math::MatrixX J_;
  math::VectorX e_;
};

}  // namespace mannequin::sim
