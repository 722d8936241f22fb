#pragma once
/// \file controller.hpp
/// \brief The mannequin's control and first-order simulation step (thesis Alg. 2 with several
/// control frames, priorities, gravity and virtual mechanisms), split so that the unilateral
/// constraint solver (Alg. 4, 3.7) slots in between.
///
/// Equations (numbers are the thesis's):
/// - dynamics b_a q̇ = Γ + Γ_gravity (2.4), b_a diagonal SPD; Γ_gravity = M J_comᵀ g;
/// - control frame i (pose oMc = oMf · offset) coupled to its target oMd by a spring-damper (2.12):
///   W_i = K_i∘e_i + B_i∘(V_d − V_i), e_i = (log(RᵀR_d), Rᵀ(p_d − p)) (couplingError, the
///   R³×SO(3) form of the thesis's log(H⁻¹H_d)), all in CONTROL-FRAME axes,
///   V_i = J_i q̇ the body twist (J_i the body Jacobian, (ω, v) order);
/// - the damping is implicit (2.17–2.20): b = b_a + Σ_i J_iᵀ diag(B_i) J_i, Γ_i = J_iᵀ(K_i∘e_i + B_i∘V_d);
/// - levels of priority (2.78–2.80): Γ_task = Σ_k Π_prev(k)ᵀ Σ_{i∈k} Γ_i, Π_prev(k) the b_a-weighted
///   projector on the kernel of all rows of levels < k (2.74); within a level, tasks are weighted
///   by their stiffnesses (2.55–2.57);
/// - internal control (2.25): Γ_int = α Π_allᵀ(k_int∘(q_d ⊖ q) + b_int∘(q̇_d − q̇_prev)), Π_all on
///   the kernel of every control frame's rows; α from the energy observer (energy.hpp);
/// - a control frame with an enabled virtual mechanism is also coupled to the mechanism's effector
///   (its K_m, B_m add to K_i's wrench and to b), and the mechanism moves under the reaction;
/// - q̇_free = b⁻¹(Γ_task + Γ_int + Γ_gravity) (2.19–2.20); q_{k+1} = q_k ⊕ q̇ δt (2.7, on SE(3)
///   for the root: Crouch–Grossman, Annex C).
///
/// Step (one call to step(), or the three stages):
///   1. computeFreeMotion(): kinematics, errors, Γ, b and its Cholesky factor, q̇ = q̇_free.
///   2. (constraint layer, optional) reads data() (kinematics at q_k), apparentFriction() (LLT of b),
///      qdotFree(); solves its LCP on J_c b⁻¹ J_cᵀ (3.7); calls applyConstraintForce(J_cᵀ W_c),
///      which adds b⁻¹ J_cᵀ W_c to q̇ (Alg. 4). Can be called several times; forces add up.
///   3. integrate(): port energies with the final q̇, mechanisms step, q ⊕ q̇ δt, energy observer; the
///      forward kinematics and CoM at the new q (data(); stage 1 of the next step reuses them).
/// No heap allocation in any stage after construction (tests/control/alloc_test.cpp).
///
/// Targets: setTarget(frame, oMd) holds a pose (V_d = 0); setTarget(frame, oMd, V_d) also gives
/// the target's BODY twist (Ḣ_d = H_d [V_d], (ω, v) in target axes; from a world angular velocity
/// ω_w and origin velocity ṗ_w: V_d = (Rᵀω_w, Rᵀṗ_w)). Non-finite or non-rotation targets throw
/// std::invalid_argument naming the frame and leave the previous target in place.
#include <optional>
#include <string>
#include <vector>

#include "mannequin/control/config.hpp"
#include "mannequin/control/energy.hpp"
#include "mannequin/control/projector.hpp"
#include "mannequin/control/virtual_mechanism.hpp"
#include "mannequin/math/tree_cholesky.hpp"
#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::control {

/// Outcome of computeFreeMotion(); numerical trouble never throws in the loop.
enum class StepStatus { kOk, kNonFinite };
/// What setTarget did with a target: taken, or refused with the previous target kept (never throws in the loop).
enum class TargetStatus { kOk, kNonFinite, kNotRotation };
/// What applyConstraintForce did: added, or refused (q̇ unchanged): a non-finite torque, or stage 1 not run.
enum class ForceStatus { kOk, kNonFinite, kNoFreeMotion };

/// What a control frame's coupling did at the last step.
struct ControlFrameState {
  std::string name;
  int frame = -1;             ///< model frame index
  int priority = 0;
  bool enabled = true;
  SE3 offset;                 ///< control frame in the model frame
  Vector6 stiffness, damping; ///< K, B (weight applied)
  SE3 target;                 ///< oMd
  Vector6 target_twist = Vector6::Zero();  ///< V_d, body twist of the target (target axes)
  SE3 pose;                   ///< oMc at the last computeFreeMotion() (q_k)
  Vector6 error = Vector6::Zero();   ///< e = couplingError(oMc, oMd), control-frame axes (rad, m)
  Vector6 wrench = Vector6::Zero();  ///< W applied by the target coupling at the last step
  Vector6 twist = Vector6::Zero();   ///< V = J q̇ after the last step (body)
  PortEnergy port;                   ///< ∫ WᵀV dt of the target coupling (2.3)
  // virtual mechanism (constrained mode)
  bool has_mechanism = false;
  bool mechanism_enabled = false;
  Vector6 mechanism_stiffness = Vector6::Zero(), mechanism_damping = Vector6::Zero();
  Vector6 mechanism_error = Vector6::Zero();   ///< couplingError(oMc, oMe)
  Vector6 mechanism_wrench = Vector6::Zero();  ///< wrench of the mechanism coupling on the frame
  PortEnergy mechanism_port;

  double positionError() const { return error.tail<3>().norm(); }  ///< m, distance to the target
  double rotationError() const { return error.head<3>().norm(); }  ///< rad
};

/// One entry of the (2.11) check: kδt/b_eff for an axis of a coupling, b_eff the apparent friction.
struct StabilityEntry {
  std::string what;  ///< "hand_r rot x", "internal knee_l", "coupled control frames" ...
  double ratio = 0;  ///< stable iff < 2, monotone iff ≤ 1
};

class Controller {
 public:
  /// Builds the controller for a model at q0 (default: standing configuration). The controller keeps a
  /// reference to the model (Model/Data: the model is shared, read-only, and must outlive the controller;
  /// a temporary model does not compile). Targets start at the current control-frame poses. Logs a warning for each unstable coupling (2.11).
  /// \throws std::invalid_argument (prefixed "FILE:LINE: field:" when the config came from a
  /// file) on unknown frame/segment names (listing the valid ones), duplicate names, non-finite
  /// or negative gains, δt ≤ 0, b_a ≤ 0, bad mechanisms, a q0 of the wrong size.
  Controller(const skeleton::Model& model, const ControllerConfig& config);
  Controller(const skeleton::Model& model, const ControllerConfig& config, const VectorX& q0);
  Controller(skeleton::Model&&, const ControllerConfig&) = delete;
  Controller(skeleton::Model&&, const ControllerConfig&, const VectorX&) = delete;

  //---- state ----
  /// q = q0, q̇ = 0, targets at the current poses, energies and observer reset, mechanisms re-attached,
  /// joint coupling cleared.
  void reset(const VectorX& q0);
  const VectorX& q() const { return q_; }          ///< (nq) configuration
  const VectorX& qdot() const { return qdot_; }    ///< (nv) velocity of the last step
  double time() const { return time_; }
  const skeleton::Model& model() const { return model_; }
  /// The mannequin's one Data. After computeFreeMotion(), until integrate(): the kinematics at q_k (poses,
  /// joint Jacobians, CoM and its Jacobian). After integrate() (and reset()): the poses and the CoM at the
  /// new q, the Jacobians still those of q_k; the next computeFreeMotion() adds the Jacobians without
  /// computing the forward kinematics again (once per step).
  const skeleton::Data& data() const { return data_; }
  const ControllerConfig& config() const { return config_; }

  //---- control frames ----
  int numFrames() const { return static_cast<int>(frames_.size()); }
  /// \throws std::invalid_argument naming the frame and listing the control frames.
  int frameIndex(const std::string& name) const;
  const ControlFrameState& frame(int i) const { return frames_.at(i); }
  /// Target pose (world) and body twist of control frame i. A non-finite value or a non-rotation R is
  /// refused (TargetStatus, the previous target kept). \throws std::invalid_argument for an index out of range.
  TargetStatus setTarget(int i, const SE3& oMd);
  TargetStatus setTarget(int i, const SE3& oMd, const Vector6& target_twist);
  /// Switches a coupling on/off (off: no wrench, no rows in the projectors' rank).
  void setFrameEnabled(int i, bool enabled);
  /// Scales K and B of a frame (gain tuning, 4.1.1). \throws on negative/non-finite.
  void setGains(int i, const Vector6& stiffness, const Vector6& damping);

  //---- virtual mechanisms (constrained mode) ----
  /// Attaches (replaces) a mechanism to frame i; allocates (not in the loop). Enabled → attached now.
  void attachMechanism(int i, const MechanismConfig& mechanism);
  /// Switches the frame between free and constrained mode; on: the effector jumps to the
  /// projection of the current control frame pose. \throws if no mechanism is attached.
  void setMechanismEnabled(int i, bool enabled);
  const VirtualMechanism& mechanism(int i) const;
  VirtualMechanism& mechanism(int i);

  //---- internal control ----
  /// q_d of the internal potential. \throws on size or non-finite.
  void setPosture(const VectorX& q_d);
  const VectorX& posture() const { return q_d_; }
  /// U(q) = ½ Σ k_int (q_d ⊖ q)² at the last computeFreeMotion() (J).
  double internalPotential() const { return potential_; }
  /// α of the internal potential (energy observer).
  double alpha() const { return observer_.alpha(); }
  const EnergyObserver& energyObserver() const { return observer_; }

  //---- joint coupling (thesis 4.4.2: a joint controller that produces a configuration change δq) ----
  /// Γ_j = k_j∘(q_j ⊖ q) − b_j∘q̇_prev on every coordinate, NOT projected and without the observer's α:
  /// a spring-damper per coordinate towards q_j, added to Γ at each step until clearJointCoupling().
  /// The balance controller in the loop (sim::World) drives the mannequin to its q ⊕ δq with it.
  /// reset() clears it (and its port).
  /// \throws std::invalid_argument on sizes (nq, nv, nv), a non-finite value or a negative gain (the message
  /// names the argument and the coordinate); the previous coupling is kept.
  void setJointCoupling(const VectorX& q_j, const VectorX& stiffness, const VectorX& damping);
  void clearJointCoupling();
  bool jointCoupling() const { return joint_coupling_; }
  const VectorX& jointCouplingTorque() const { return gamma_j_; }  ///< Γ_j of the last stage 1 (nv)
  const PortEnergy& jointCouplingPort() const { return port_joint_; }

  //---- the step ----
  StepStatus step();                       ///< computeFreeMotion() then integrate()
  StepStatus computeFreeMotion();          ///< stage 1
  /// Stage 2: q̇ += b⁻¹ Γ_c with Γ_c = J_cᵀ W_c (nv). A non-finite Γ_c, or a call before stage 1, is refused
  /// (ForceStatus, q̇ unchanged). \throws std::invalid_argument on a size other than nv (MANNEQUIN_CHECK_ARGUMENT_SIZE).
  ForceStatus applyConstraintForce(const VectorX& gamma_c);
  void integrate();                        ///< stage 3
  /// b = b_a + Σ JᵀBJ at q_k (nv × nv) and its Cholesky factor b = Lᵀ L along the tree of coordinates
  /// (reuse it: b⁻¹x by factor.solveInPlace(x)).
  /// (dense, built from the assembled pattern when asked: the step itself assembles and factorises b
  /// on the tree's pattern only)
  const MatrixX& apparentFriction() const;
  const math::TreeCholesky& apparentFrictionFactor() const { return factor_; }
  const VectorX& qdotFree() const { return qdot_free_; }
  const VectorX& frictionDiagonal() const { return b_a_; }   ///< b_a (nv)
  /// Torques of the last stage 1 (nv each).
  const VectorX& taskTorque() const { return gamma_task_; }
  const VectorX& internalTorque() const { return gamma_int_; }
  const VectorX& gravityTorque() const { return gamma_g_; }
  /// Stacked body Jacobians of the control frames (6·numFrames × nv) in PRIORITY order: the 6 rows
  /// of frame i start at frameRow(i). Disabled frames have zero rows.
  const MatrixX& taskJacobian() const { return J_; }
  int frameRow(int i) const { return frame_row_.at(i); }

  //---- energy (2.3) ----
  const PortEnergy& internalPort() const { return port_internal_; }
  const PortEnergy& gravityPort() const { return port_gravity_; }
  const PortEnergy& constraintPort() const { return port_constraint_; }
  const PortEnergy& dissipation() const { return dissipated_; }   ///< ∫ q̇ᵀ b_a q̇ dt ≥ 0

  //---- checks ----
  /// kδt/b_eff for every axis of every enabled coupling at the current q, the coupled system
  /// (δt·λ_max(K^½ J b⁻¹ Jᵀ K^½)) and the internal stiffness (k_int δt / b_a). Allocates.
  std::vector<StabilityEntry> checkStability();
  long nonFiniteSteps() const { return non_finite_steps_; }

 private:
  void build(const VectorX& q0);
  void frameKinematics();    // FK, Jacobians, control-frame poses and body Jacobian rows
  void couplingTerms();      // K∘e + B∘V_d (+ mechanism) per frame, sqrt(B)·J rows
  void assembleFriction();   // b = b_a + Σ JᵀBJ and its LLT
  void checkFrame(int i) const;
  std::string describe(int i) const;

  const skeleton::Model& model_;
  skeleton::Data data_;
  bool kinematics_at_q_ = false;  // data_'s poses are those of q_ (forward kinematics done)
  ControllerConfig config_;
  int nv_ = 0, rows_ = 0;
  double dt_ = 1e-3;
  std::vector<ControlFrameState> frames_;
  std::vector<std::vector<int>> support_cols_;  // per frame: velocity columns that move it
  std::vector<std::optional<VirtualMechanism>> mechanisms_;  // one slot per frame
  std::vector<int> level_begin_;                // first frame of each priority level (frames sorted)
  std::vector<int> order_;                      // frames in priority order
  std::vector<int> frame_row_;                  // per frame: first row in J_

  VectorX q_, qdot_, qdot_prev_, qdot_free_, q_next_;
  VectorX b_a_, b_a_inv_, k_int_, b_int_, q_d_, dq_int_, gamma0_;
  VectorX gamma_task_, gamma_level_, gamma_int_, gamma_g_, gamma_c_, gamma_, tmp_;
  MatrixX J_;      // (rows × nv) body Jacobians in priority order
  MatrixX JB_;     // (rows × nv) sqrt(B)·J
  // b on the tree's pattern, packed as factor_ reads it: the diagonal and the entries b_ki (i an
  // ancestor of k) at factor_.packedIndex(k, i); b_slots_[f]: per frame, for its support columns
  // a > b (in support order), the packed index of b(cols[a], cols[b]), row by row
  VectorX b_diag_, b_lower_;
  std::vector<std::vector<int>> b_slots_;
  mutable MatrixX b_;      // (nv × nv) dense b, built by apparentFriction() from the packed pattern
  mutable bool b_stale_ = true;
  // b = Lᵀ L along the model's tree of coordinates (no fill-in: b has the tree's sparsity)
  math::TreeCholesky factor_;
  // J_ is sparse: a frame's rows are zero off its support columns. b_'s Σ JᵀBJ and the projectors'
  // Gram J b_a⁻¹ Jᵀ are summed over those columns only (frame pairs: the columns both frames share).
  struct FramePair {
    int frame_a = 0, frame_b = 0;  // frame_row_[frame_a] >= frame_row_[frame_b]
    std::vector<int> cols;         // velocity columns in both supports
  };
  std::vector<FramePair> frame_pairs_;
  MatrixX gram_;   // (rows × rows) J b_a⁻¹ Jᵀ, lower triangle
  void gramOfTasks();
  void factorGramOfTasks();  // gramOfTasks() and gram_factor_ of it
  // projector: ldlt — one unpivoted factorisation of gram_ serves every level and the internal control
  PriorityGramFactor gram_factor_;
  // projector: svd — one SVD per projector
  std::vector<WeightedNullSpace> level_projectors_;  // [k] for level k ≥ 1: rows of levels < k
  WeightedNullSpace internal_projector_;
  std::vector<Vector6> wrench_ff_;  // per frame: K∘e + B∘V_d (+ mechanism part)
  std::vector<Vector6> damping_total_;
  std::vector<Vector6> vd_c_;       // per frame: target twist in control-frame axes
  std::vector<Vector6> ve_c_;       // per frame: mechanism effector twist in control-frame axes
  double total_mass_ = 0.0;

  EnergyObserver observer_;
  double potential_ = 0.0;
  bool have_internal_power_ = false;
  PortEnergy port_internal_, port_gravity_, port_constraint_, dissipated_, port_joint_;
  bool joint_coupling_ = false;
  VectorX q_j_, k_j_, b_j_, dq_j_, gamma_j_;  // joint coupling (nq, nv, nv, nv, nv)
  double time_ = 0.0;
  long non_finite_steps_ = 0;
  bool free_motion_ready_ = false;
};

}  // namespace mannequin::control
