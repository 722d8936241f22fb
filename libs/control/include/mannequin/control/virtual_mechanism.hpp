#pragma once
/// \file virtual_mechanism.hpp
/// \brief Virtual mechanisms (thesis 2.2.2.2 "Mécanismes virtuels", 4.1.1 "Mode de commande
/// contraint", Fig. 2.20, 2.21, 4.1): a passive mechanism simulated next to the mannequin, whose
/// end-effector a control frame is coupled to. The control frame is then guided on what the
/// effector can reach (a line, an axis, a plane, a curve) while the operator's target still drives
/// it along the free directions.
///
/// Every mechanism has coordinates s ∈ R^d (d ≤ 4), a base frame oMb (world) and an effector pose
/// oMe(s). Its first-order dynamics, like the mannequin's (2.4), is
///     b_m ṡ = J_mᵀ W_e + f                                                (one row per coordinate)
/// with J_m the effector's BODY Jacobian (twist (ω, v) in the effector frame), W_e the coupling
/// wrench on the effector (effector frame), b_m its viscous friction and f the coordinate
/// forces: 0 leaves a direction free; a non-zero f on a coordinate makes it force-controlled
/// (hybrid position/force, Fig. 4.1: "move on the plane, push with a set force along its normal").
/// End stops clamp s into [lower, upper] (Fig. 2.21); a coordinate with lower == upper is locked.
///
/// Types and coordinates (axes are those of the base frame b):
/// - kPrismatic     s = (t):          oMe = oMb · (I, t·z)                         line along z
/// - kSlidingPivot  s = (t, θ):       oMe = oMb · (Rz(θ), t·z)   cylindrical joint: the drill of Fig. 2.20
/// - kPlane         s = (x, y, θ, n): oMe = oMb · (Rz(θ), (x, y, n))  planar joint; n (along the normal z)
///                                    is locked at 0 unless a normal force is set (hybrid)
/// - kCurve         s = (u):          oMe = (R_b, c(u)), c a curve through the points (world),
///                                    u ∈ [0, npoints − 1]; Catmull–Rom spline (C¹) or polyline (C⁰)
#include <string>
#include <vector>

#include "mannequin/control/first_order.hpp"

namespace mannequin::control {

enum class MechanismType { kPrismatic, kSlidingPivot, kPlane, kCurve };

/// "prismatic", "sliding_pivot", "plane", "curve".
const char* toString(MechanismType type);
/// Inverse of toString. \throws std::invalid_argument listing the valid names.
MechanismType mechanismTypeFromString(const std::string& name);
/// Number of coordinates d of a type (1, 2, 4, 1).
int mechanismDimension(MechanismType type);

/// Maximum number of mechanism coordinates (fixed-size buffers, no allocation in the loop).
inline constexpr int kMaxMechanismDim = 4;
using MechVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxMechanismDim, 1>;
using MechJacobian = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxMechanismDim>;

/// What a mechanism is (data; see the file comment for the coordinates).
struct MechanismSpec {
  MechanismType type = MechanismType::kPrismatic;
  SE3 base;                     ///< oMb: base frame in the world (axis / normal = its z)
  std::vector<Vector3> points;  ///< kCurve only: points in the world (≥ 2), passed through in order
  bool spline = true;           ///< kCurve: Catmull–Rom (C¹) if true, polyline (C⁰) otherwise
  double friction = 1.0;        ///< b_m (> 0), same for every coordinate (N·s/m or N·m·s/rad)
  /// End stops (d each; empty = defaults: free, except kPlane's n locked at 0 and kCurve's u ∈ [0, npoints−1]).
  VectorX lower, upper;
  /// Coordinate forces f (d; empty = zeros). For kPlane, force(3) = −F pushes the control frame
  /// with F newtons into the plane (along −z); setting it also unlocks n unless stops say otherwise.
  VectorX force;
};

/// A virtual mechanism with its state s, ṡ. Built once (allocates), then stepped without allocation.
class VirtualMechanism {
 public:
  /// \throws std::invalid_argument on a bad spec (curve with < 2 points or repeated points,
  /// non-finite values, friction ≤ 0, lower > upper, wrong sizes).
  explicit VirtualMechanism(MechanismSpec spec);

  const MechanismSpec& spec() const { return spec_; }
  int dim() const { return dim_; }
  const MechVector& s() const { return s_; }
  const MechVector& sdot() const { return sdot_; }
  void setCoordinates(const MechVector& s);  ///< clamped to the stops; ṡ = 0
  /// Sets the coordinate forces f (size d). \throws std::invalid_argument on size or NaN.
  void setForce(const VectorX& f);

  /// Effector pose oMe(s) in the world.
  SE3 pose() const { return poseAt(s_); }
  SE3 poseAt(const MechVector& s) const;
  /// Body Jacobian of the effector (6 × d, twist (ω, v) in the effector frame) at s.
  void jacobian(const MechVector& s, MechJacobian& J) const;
  /// Effector body twist J_m ṡ.
  Vector6 twist() const;

  /// Coordinates whose effector is closest to the pose oMc (position first; rotation about z for
  /// sliding pivot and plane), clamped to the stops. Used when a control frame attaches.
  MechVector project(const SE3& oMc) const;
  /// s = project(oMc), ṡ = 0.
  void attachTo(const SE3& oMc) { setCoordinates(project(oMc)); }

  /// One explicit Euler step of the mechanism coupled to a control frame at oMc moving with body
  /// twist V_c (control-frame axes), through a spring-damper K, B (per axis, effector axes):
  ///   (b_m I + J_mᵀ B J_m) ṡ = J_mᵀ (K∘couplingError(oMe, oMc) + B∘(Ad_{eMc} V_c)) + f,  s += ṡ δt, clamped.
  /// The coupling damper is implicit (like b = b_a + JᵀB_cJ in 2.17). A clamped coordinate gets ṡ = 0.
  void step(const SE3& oMc, const Vector6& V_c, const Vector6& K, const Vector6& B, double dt);

  /// Effector point and tangent of a curve at u (world), for tests. kCurve only.
  void curveAt(double u, Vector3& c, Vector3& dc) const;

 private:
  MechanismSpec spec_;
  int dim_ = 1;
  MechVector s_, sdot_, lower_, upper_, force_;
};

}  // namespace mannequin::control
