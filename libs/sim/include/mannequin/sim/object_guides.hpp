#pragma once
/// \file object_guides.hpp
/// \brief Guides on objects (thesis 4.1.1 "mécanismes virtuels", 4.3.1: the waiter's tray kept level,
/// the rotor part whose holes are kept aligned, the pin kept on the hole's axis): a free constraints::RigidObject's
/// frame (its body frame, origin at the centre of mass) is kept on the effector manifold of a virtual
/// mechanism by rows of the World's LCP on the object alone (RowSource::kGuide). Where the control
/// library's mechanisms (virtual_mechanism.hpp) guide a HAND through a spring, a guide holds the OBJECT
/// rigidly: whoever pushes it (a hand that grasps it, a contact) moves it only along the mechanism.
///
/// With the base frame oMb (world) and the object's pose oMo, the relative pose bMo = (R, r),
/// r = R_bᵀ(p_o − p_b) (base axes), and the mechanism's coordinates read off it:
///   prismatic      t = r_z;                  locked: r_x = r_y = 0, R = I
///   sliding_pivot  t = r_z, θ = atan2(R₁₀, R₀₀); locked: r_x = r_y = 0, z_o = z_b
///   plane          x = r_x, y = r_y, θ, n = r_z; locked: z_o = z_b (n at its stops: [0, 0] by default)
/// (curves are not supported on objects). Rows, all with the object's point Jacobian J_p(p_o) and its
/// angular-velocity Jacobian J_ω (world), ν the object's body twist:
///   a locked position axis i:  d = r_i,                         J = (R_b e_i)ᵀ J_p        bilateral
///   R = I (prismatic):         d = log(R_o R_bᵀ)_i,              J = e_iᵀ J_l⁻¹(d) J_ω    bilateral, world axes
///   z_o = z_b (axis aligned):  d_i = (R_b e_i)ᵀ (z_b × z_o),    J = −(R_b e_i)ᵀ [z_b]× [z_o]× J_ω,  i = x, y
///                              (the exact derivative; d_x, d_y are the small tilts about the base x, y axes)
///   a coordinate c with stops: lower == upper: bilateral d = c − lower; otherwise, within `activation` of
///                              a finite stop, unilateral d = c − lower (J = +∂c) or upper − c (J = −∂c),
///                              ∂t = (R_b e_z)ᵀ J_p, ∂θ = (R_b e_z)ᵀ J_ω (exact when the axes are aligned).
/// A guide attached away from its manifold brings the object onto it at most at `recovery_speed` (m/s or
/// rad/s per row: the solver caps |d|/δt), so it never jumps.
#include <vector>

#include "mannequin/constraints/solver.hpp"
#include "mannequin/control/virtual_mechanism.hpp"
#include "mannequin/constraints/objects.hpp"

namespace mannequin::sim {

class GuideRows final : public constraints::RowProducer {
 public:
  /// `objects[i]` is object i, `object_systems[i]` its system index in the solver.
  /// \throws std::invalid_argument on sizes that differ, a null object, a negative system, activation or
  /// recovery_speed ≤ 0.
  GuideRows(std::vector<const constraints::RigidObject*> objects, std::vector<int> object_systems, double activation = 0.05,
            double recovery_speed = 0.3);
  const char* name() const override { return "guides"; }

  /// Whether `spec` can guide an object; false with the reason in `why` (a curve, coordinate forces,
  /// non-finite values, lower > upper, stops of the wrong size).
  static bool supports(const control::MechanismSpec& spec, std::string* why = nullptr);
  /// Guides object `object` on `spec` (replacing a guide it had). Allocates (the spec's vectors): call
  /// it from a scenario action, not in a tight loop. \throws std::invalid_argument on a bad object index,
  /// a hinged object, or a spec supports() refuses (the reason in the message).
  void attach(int object, const control::MechanismSpec& spec);
  /// Ends object `object`'s guide; false if it had none.
  bool detach(int object);
  bool guided(int object) const;
  /// The guided coordinates of object `object` now (prismatic t; sliding pivot t, θ; plane x, y, θ, n),
  /// and its distance from the manifold (m, the largest |d| of its locked position rows, and rad, of
  /// its locked rotation rows). Zeros for an object without a guide.
  control::MechVector coordinates(int object) const;
  double positionError(int object) const;
  double angleError(int object) const;
  /// Force (N, world) the guide applied on the object at the last solve (its position rows).
  math::Vector3 force(int object) const;

  void addRows(int id, double dt, constraints::RowSet& rows) override;
  void solved(int id, const constraints::RowSet& rows) override;

 private:
  struct Guide {
    bool active = false;
    control::MechanismSpec spec;
    Eigen::Vector4d lower, upper;  // per coordinate (free: ∓inf)
    math::Vector3 force = math::Vector3::Zero();
  };
  struct Geometry;  // the relative pose's readings (object_guides.cpp)
  Geometry measure(int object) const;

  std::vector<const constraints::RigidObject*> objects_;
  std::vector<int> systems_;
  std::vector<Guide> guides_;
  double activation_, recovery_speed_;
  Eigen::Matrix3Xd Jp_, Jw_, J1_;
};

}  // namespace mannequin::sim
