#pragma once
/// \file kinetics.hpp
/// \brief Whole-body kinetics of one posture in motion and of a whole motion: the external wrench the
/// motion needs, the contact forces that provide it, the residual no contact explains, the joint torques.
///
/// For a sample (q, v, a) (motion.hpp), with known loads L_j (a carried box's weight at the hands):
/// 1. inverse dynamics with the loads (skeleton::rnea): the root's wrench W is what the environment
///    must apply — the rate of the body's momentum minus its weight and the loads (world, about the
///    world origin);
/// 2. W is shared among the active contacts (contact_wrench.hpp); what they cannot carry is the
///    residual wrench (force; moment about the CoM), the force no contact explains — OpenSim's
///    "residual" (Hicks et al. 2015, "Is my model good enough?");
/// 3. inverse dynamics again with the contact forces and the loads applied at their points: the joint
///    torques τ (nv; the root's six entries are the residual, in the root's body frame).
#include <vector>

#include "mannequin/kinetics/contact_wrench.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::kinetics {

using math::VectorX;

/// A known external force on the body (world): e.g. the weight of a carried object at a hand.
struct Load {
  int joint = -1;                    ///< the model joint whose body carries it
  Vector3 point = Vector3::Zero();   ///< where it acts (m, world)
  Vector3 force = Vector3::Zero();   ///< N, world
};

/// Options of KineticsSolver.
struct KineticsOptions {
  Vector3 gravity = Vector3(0, 0, -9.81);  ///< m/s², world
  DistributionOptions distribution;
};

/// The kinetics of one sample (world frame).
struct KineticsFrame {
  Vector3 com = Vector3::Zero();                 ///< m
  Vector6 required_wrench = Vector6::Zero();     ///< W: (moment about the origin, force) the environment must give
  std::vector<Vector3> contact_forces;           ///< N, per contact given, on the body
  Vector3 contact_force = Vector3::Zero();       ///< Σ contact forces (N): the ground (and scene) reaction
  Vector3 residual_force = Vector3::Zero();      ///< N
  Vector3 residual_moment = Vector3::Zero();     ///< N·m, about the CoM
  VectorX tau;                                   ///< joint torques (nv)
  lcp::LcpStatus status = lcp::LcpStatus::Invalid;  ///< of the contact-force LCP
};

/// Computes KineticsFrames of one model (owns its skeleton::Data; one per thread).
class KineticsSolver {
 public:
  explicit KineticsSolver(const skeleton::Model& model, KineticsOptions options = {});
  /// The kinetics of (q, v, a) with these contacts and loads (see the file comment).
  /// \throws std::invalid_argument on sizes, non-finite values, or a contact/load on an unknown joint.
  KineticsFrame solve(const VectorX& q, const VectorX& v, const VectorX& a, const std::vector<ContactPoint>& contacts,
                      const std::vector<Load>& loads = {});
  const skeleton::Model& model() const { return model_; }

 private:
  const skeleton::Model& model_;
  KineticsOptions options_;
  skeleton::Data data_;
  std::vector<Vector6> fext_;
};

/// What a motion's kinetics add up to (the reporting keys of mannequin-simulate and mannequin-batch).
struct KineticsSummary {
  int frames = 0;
  double weight_n = 0;                ///< m g of the model
  double grf_mean_over_weight = 0;    ///< time-averaged vertical contact force / weight
  double residual_force_mean_n = 0;   ///< mean |residual force|
  double residual_force_peak_n = 0;   ///< max |residual force|
  double residual_moment_peak_nm = 0; ///< max |residual moment about the CoM|
  double peak_external_force_n = 0;   ///< max |Σ contact forces|
};

/// Sums frames sampled at a constant rate. \throws std::invalid_argument if weight_n ≤ 0.
KineticsSummary summarize(const std::vector<KineticsFrame>& frames, double weight_n);

}  // namespace mannequin::kinetics
