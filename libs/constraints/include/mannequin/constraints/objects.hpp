#pragma once
/// \file objects.hpp
/// \brief Rigid objects of a scene (thesis 3.2, 4.3.1: ball, tray, door, throttle lever) as systems
/// of the constraint layer, with the same first-order dynamics as the mannequins (thesis 2.4):
///   b ν = W_gravity + W_ext + W_c.
///
/// Two kinds:
/// - a FREE body (nv = 6): ν = (ω, v) is its BODY twist (angular first, like the skeleton's
///   free-flyer root), Ḣ = H[ν]; b = diag(I_body/τ, m/τ·1₃) with I_body the principal moments in the
///   body frame, whose origin is the centre of mass; the pose is integrated on SE(3):
///   H_{k+1} = H_k exp(δt ν);
/// - a HINGED body (nv = 1): ν = θ̇, a rotation by θ about the world axis a through the world point c,
///   H(θ) = T(c) Rot(a, θ) T(−c) H(0); b = I_a/τ with I_a = aᵀ R₀ I_body R₀ᵀ a + m |a × (x_G − c)|²
///   (parallel axes); limits lower ≤ θ ≤ upper by HingeLimitRows.
///
/// The time constant τ: b is a friction, not an inertia. Under a constant force F alone a free
/// body reaches at once the speed F/b_lin = F τ/m, i.e. it falls at the TERMINAL speed m g/b_lin = g τ
/// (0.49 m/s for τ = 0.05 s) and it stops as soon as the force does (no ballistic flight, no bounce).
/// τ is the time a real body of the same mass would take to reach that speed from rest under the
/// same force: small τ makes objects stiff to push and slow to fall; the default 0.05 s keeps a
/// dropped ball's fall visible and a door's swing stopped when the hand leaves. Like the mannequin's
/// controller, what matters for the constraints is that at rest the forces balance exactly: on a
/// support the contact forces equal the weight (ν = 0 ⇔ W_c = −W_g).
///
/// Stages per step (Alg. 4), none throws or allocates:
///   computeFreeMotion(gravity, δt): ν_free = b⁻¹(W_g + W_ext) (W_ext: addForce since the last step);
///   applyConstraintForce(Γ_c):       ν = ν_free + b⁻¹ Γ_c (ConstrainedSystem, by the ConstraintSolver);
///   integrate(δt):                   the pose (or θ), then W_ext is cleared.
/// As a constraints::BodyFrames it has one body (local 0): pose(0) and the point Jacobian
///   free:  ṗ = R (v + ω × p_local), p_local = Rᵀ(p − o)  →  J = [−R[p_local]×, R];
///   hinge: ṗ = θ̇ a × (p − c)                              →  J = a × (p − c).
#include <optional>
#include <string>
#include <vector>

#include "mannequin/collision/scene.hpp"
#include "mannequin/constraints/bodies.hpp"
#include "mannequin/constraints/solver.hpp"
#include "mannequin/constraints/system.hpp"
#include "mannequin/math/se3.hpp"

namespace mannequin::constraints {

struct RigidObjectSpec {
  std::string name;
  math::SE3 pose;                  ///< initial world pose of the body frame (origin at the centre of mass)
  double mass = 1.0;               ///< kg, > 0
  math::Vector3 inertia = math::Vector3::Constant(0.01);  ///< principal moments, body frame (kg·m²), > 0
  double time_constant = 0.05;     ///< τ (s), > 0
  std::optional<collision::HingeSpec> hinge;  ///< none: free body
};

class RigidObject final : public constraints::ConstrainedSystem, public constraints::BodyFrames {
 public:
  /// \throws std::invalid_argument naming the object on a non-positive or non-finite mass, inertia or
  /// τ, a zero hinge axis, lower > 0 or upper < 0 (the initial angle 0 must be within the limits).
  explicit RigidObject(const RigidObjectSpec& spec);

  const std::string& name() const { return name_; }
  bool hinged() const { return hinged_; }
  double mass() const { return mass_; }
  double timeConstant() const { return tau_; }

  // -- stages of a step --
  /// ν_free = b⁻¹(W_g + W_ext), W_g the weight m·gravity (world, m/s²) at the centre of mass.
  void computeFreeMotion(const math::Vector3& gravity, double dt);
  /// Integrates the pose with ν (after the constraints); clears the external forces.
  void integrate(double dt);
  /// Adds a world force (N) at a world point (m) to the next free motion (a push, a test's load).
  void addForce(const math::Vector3& point, const math::Vector3& force);

  // -- ConstrainedSystem --
  int nv() const override { return hinged_ ? 1 : 6; }
  const Eigen::VectorXd& qdotFree() const override { return qdot_free_; }
  const math::TreeCholesky& frictionFactor() const override { return factor_; }
  bool applyConstraintForce(const Eigen::VectorXd& gamma_c) override;

  // -- BodyFrames (one body, local 0) --
  const math::SE3& pose(int local = 0) const override;
  void pointJacobian(int local, const math::Vector3& p, Eigen::Ref<Eigen::Matrix3Xd> J) const override;

  /// ν after the constraints (body twist (ω, v), or θ̇).
  const Eigen::VectorXd& velocity() const { return qdot_; }
  /// The apparent friction b (nv × nv, diagonal).
  const Eigen::MatrixXd& friction() const { return b_; }
  /// Hinge angle θ (rad; 0 at the initial pose); 0 for a free body.
  double angle() const { return theta_; }
  const collision::HingeSpec& hinge() const { return hinge_; }
  /// Moves the object (tests, resets): a free body takes `H`; a hinged body takes an angle (setAngle).
  /// Velocities and external forces are cleared.
  void setPose(const math::SE3& H);
  void setAngle(double theta);
  /// World velocity of the material point at p (m/s) with the current ν.
  math::Vector3 pointVelocity(const math::Vector3& p) const;

 private:
  void updateHingePose();

  std::string name_;
  bool hinged_ = false;
  double mass_ = 1.0, tau_ = 0.05;
  math::Vector3 inertia_;
  collision::HingeSpec hinge_;
  math::SE3 pose0_, pose_;
  double theta_ = 0.0;
  Eigen::MatrixXd b_;
  Eigen::VectorXd b_inv_;  // diagonal of b⁻¹
  math::TreeCholesky factor_;  // b is diagonal: no parents
  Eigen::VectorXd qdot_free_, qdot_;
  math::Vector3 ext_force_ = math::Vector3::Zero();   // world, at the centre of mass
  math::Vector3 ext_moment_ = math::Vector3::Zero();  // world, about the centre of mass
};

/// Builds a RigidObject for every movable body of `scene` with dynamics (BodySpec::dynamics), in the
/// order of scene.bodies; `body_index[i]` receives the index in scene.bodies of object i (the World
/// maps it to the CollisionWorld's body id). τ: the body's time_constant, else `default_time_constant`.
/// \throws std::invalid_argument naming the body on bad dynamics.
std::vector<RigidObject> makeObjects(const collision::SceneSpec& scene, std::vector<int>* body_index = nullptr,
                                     double default_time_constant = 0.05);

/// A hinged object's limits as unilateral rows (RowSource::kHinge): for θ within `activation` of a
/// limit, d = θ − lower (J = +1) or d = upper − θ (J = −1). The predictive row d + δt J θ̇ ≥ 0 is
/// exact for an angle (linear in θ̇), so the limit holds to the LCP's precision.
class HingeLimitRows final : public constraints::RowProducer {
 public:
  struct Entry {
    const RigidObject* object = nullptr;
    int system = -1;  ///< the object's index in the ConstraintSolver
  };
  /// Free bodies and hinges without limits in `objects` are skipped. \throws std::invalid_argument on
  /// a null object or a negative system index.
  explicit HingeLimitRows(std::vector<Entry> objects, double activation = 0.2, double recovery_speed = 1.0);
  const char* name() const override { return "hinge_limits"; }
  void addRows(int id, double dt, constraints::RowSet& rows) override;

 private:
  std::vector<Entry> objects_;
  double activation_, recovery_speed_;
};

/// Grasps (thesis 4.3.1): while held, an object's frame is kept on a hand frame by 6 BILATERAL rows
/// (RowSource::kGrasp): with the target oMt = oMh · hMo (hMo the relative pose when grasped),
///   position    d_i = e_iᵀ (o_o − o_t),           J_i = e_iᵀ (J_p,obj(o_o) − J_p,hand(o_o))   i = x, y, z
///   orientation d_i = e_iᵀ log(R_o R_tᵀ),          J_i = e_iᵀ (J_ω,obj − J_ω,hand)
/// (world axes e_i; J_ω, the angular velocity Jacobian, is read from point Jacobians: for a rigid
/// body J_p(x + e_j) − J_p(x) = [ω]× e_j exactly, so ω_x = (J_p(x+e_y) − J_p(x))_z etc.). The forces
/// λ act on both systems: the object's weight reaches the hand's system as −J_handᵀλ.
class GraspRows final : public constraints::RowProducer {
 public:
  /// The hand side: a body of a system (a mannequin's palm joint, or any BodyFrames).
  struct Hand {
    int system = -1;
    const constraints::BodyFrames* frames = nullptr;
    int local = 0;
  };
  /// `objects[i]` is object i and `object_systems[i]` its system index; `max_nv` the largest nv of a
  /// hand system (buffers); at most `max_grasps` grasps at a time.
  /// \throws std::invalid_argument on sizes that differ, a null object, max_nv < 1.
  GraspRows(std::vector<const RigidObject*> objects, std::vector<int> object_systems, int max_nv,
            int max_grasps = 8, double recovery_speed = 0.5);
  const char* name() const override { return "grasps"; }

  /// Grasps object `object` with `hand` at their current relative pose. Several hands may hold one
  /// object (two hands, two mannequins carrying a box: a closed chain whose rows stay independent as
  /// each hand brings its own arm's joints). Returns a handle ≥ 0, or −1 (bad object index, hand
  /// without frames or system, this hand already holds it, no free slot). No allocation.
  int grasp(const Hand& hand, int object);
  /// Releases a grasp; false for an unknown handle.
  bool release(int handle);
  bool held(int object) const;
  int numGrasps() const;

  void addRows(int id, double dt, constraints::RowSet& rows) override;
  void solved(int id, const constraints::RowSet& rows) override;

  /// Force (N, world) and moment (N·m, world) the rows of grasp `handle` applied ON THE OBJECT at the
  /// last solve (λ of the position and orientation rows); the hand gets the opposite.
  math::Vector3 force(int handle) const;
  math::Vector3 moment(int handle) const;

 private:
  struct Grasp {
    bool active = false;
    Hand hand;
    int object = -1;
    math::SE3 hMo;
    int first_row = -1;
    math::Vector3 force = math::Vector3::Zero(), moment = math::Vector3::Zero();
  };
  void angularJacobian(const constraints::BodyFrames& frames, int local, const math::Vector3& x, int nv,
                       Eigen::Matrix3Xd& Jw);

  std::vector<const RigidObject*> objects_;
  std::vector<int> systems_;
  std::vector<Grasp> grasps_;
  double recovery_speed_;
  Eigen::Matrix3Xd Jp_obj_, Jw_obj_, Jp_hand_, Jw_hand_, J0_, J1_;
};

}  // namespace mannequin::constraints
