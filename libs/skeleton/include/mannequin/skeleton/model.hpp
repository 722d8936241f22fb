#pragma once
/// \file model.hpp
/// \brief The mannequin's kinematic tree (joints, segments, frames) and its per-step buffers.
///
/// `Model` is built once (see anthropometry.hpp) and then only read; `Data` holds every buffer
/// the algorithms write, preallocated from the Model so that the real-time loop never allocates
/// (pinocchio's Model/Data, MuJoCo's mjModel/mjData).
///
/// Joints and their coordinates (thesis 1.13 and Annex D.1):
/// - kRevolute (pivot): q ∈ R (rad), v = q̇; transform exp([ξ] q) about a unit axis ξ of the joint frame.
/// - kBall: q ∈ so(3) ≅ R³, the rotation vector of the joint (R = exp([q]), Annex D.1);
///   v ∈ R³ is the angular velocity of the child in its own frame (body frame).
/// - kFreeFlyer (the root on SE(3)): q = (p, r) ∈ R³×R³, pose [exp(r), p] in the world;
///   v = (ω, v) ∈ R⁶ is the body twist of the root (angular first, thesis convention).
/// So nq == nv for every joint, but q is not a vector space: use integrate()/difference()
/// (kinematics.hpp), never q + v.
#include <limits>
#include <string>
#include <vector>

#include "mannequin/math/se3.hpp"

namespace mannequin::skeleton {

using math::Matrix3;
using math::Matrix3X;
using math::Matrix6X;
using math::SE3;
using math::Vector3;
using math::Vector6;
using math::VectorX;

enum class JointType { kRevolute, kBall, kFreeFlyer };

/// Name of a joint type as written in configs ("revolute", "ball", "free_flyer").
const char* toString(JointType type);

/// Swing/twist limits of a ball joint (thesis Annex D.2, after Baerlocher & Boulic). The ball's
/// rotation R (child in the joint placement frame, R = exp([q])) is split R = R_s R_t about the
/// TWIST AXIS t (unit, joint frame; the child segment's long axis, from the joint centre to its CoM):
/// R_s the geodesic rotation taking t to R t, with rotation vector s = θ_s u ⟂ t (θ_s ∈ [0, π]),
/// R_t = exp(θ_t [t]) the rest, θ_t ∈ (−π, π] the signed twist angle. Limits:
/// - swing: the ellipse ((s·e1 − c_x)/a)² + ((s·e2 − c_y)/b)² ≤ 1 on the swing vector (rad), e1, e2
///   an orthonormal basis of the plane ⟂ t (joint frame);
/// - twist: θ_t ∈ [twist_lower, twist_upper] (rad).
/// The ellipse must contain s = 0 and stay inside |s| ≤ kMaxSwing (the decomposition is singular
/// at θ_s = π); checkBallLimit() says what is wrong.
struct BallLimit {
  /// Largest swing on an ellipse (rad). The swing/twist rows' Jacobians grow like θ_s/sin θ_s and
  /// their curvature like 1/sin²θ_s: at 150° (≤ 5.2×) the constraint layer keeps fast arms inside
  /// the cone (tests/constraints/joint_limit_rows_test.cpp); at 170° (17×) a step of 0.05 rad turned
  /// the twist by ~0.5 rad and the swing went into the singular band (issue 13).
  static constexpr double kMaxSwing = 150.0 * 3.14159265358979323846 / 180.0;
  static constexpr double kMaxTwist = 170.0 * 3.14159265358979323846 / 180.0;  ///< rad
  bool enabled = false;
  Vector3 twist_axis = -Vector3::UnitZ();  ///< t, unit, joint frame
  Vector3 swing_x = Vector3::UnitX();      ///< e1, unit, ⟂ t
  Vector3 swing_y = Vector3::UnitY();      ///< e2, unit, ⟂ t and e1
  double swing_a = 1.0, swing_b = 1.0;     ///< semi-axes along e1, e2 (rad, > 0)
  double swing_cx = 0.0, swing_cy = 0.0;   ///< centre of the ellipse (rad); the thesis's form is c = 0
  double twist_lower = -1.0, twist_upper = 1.0;  ///< rad
  /// Largest |s| on the ellipse (rad), by sampling 720 points.
  double maxSwing() const;
};

/// Empty when `limit` is usable, else what is wrong (non-unit or non-orthogonal axes, a ≤ 0,
/// an ellipse not containing 0 or reaching past kMaxSwing, a twist range not containing 0 or
/// outside ±kMaxTwist, a non-finite value).
std::string checkBallLimit(const BallLimit& limit);

/// An orthonormal basis (e1, e2) of the plane ⟂ t: Gram–Schmidt of the joint frame's x then y
/// axes (y then z when t ∥ x). For t = ±z: e1 = x, e2 = y.
void swingBasis(const Vector3& t, Vector3& e1, Vector3& e2);

/// One joint of the tree; each joint carries a moving frame ("joint frame").
struct Joint {
  std::string name;
  JointType type = JointType::kRevolute;
  int parent = -1;                  ///< parent joint index, -1 for the world
  SE3 placement;                    ///< joint frame in the parent joint frame at q = 0 (jMi(0))
  Vector3 axis = Vector3::UnitZ();  ///< revolute only: unit axis ξ in the joint frame
  int idx_q = 0;                    ///< first coordinate in q
  int idx_v = 0;                    ///< first coordinate in v
  int nq = 0;                       ///< coordinates (1, 3 or 6)
  int nv = 0;                       ///< velocity coordinates (== nq)
  BallLimit ball_limit;             ///< ball only: swing/twist limits (disabled: none)
};

/// A capsule for collision: the segment line from `a` to `b` (joint frame) swept by a sphere.
struct Capsule {
  Vector3 a = Vector3::Zero();  ///< first end of the axis, joint frame (m)
  Vector3 b = Vector3::Zero();  ///< second end of the axis, joint frame (m)
  double radius = 0.0;          ///< (m)
  double length() const { return (b - a).norm(); }
};

/// A rigid segment (body) carried by a joint.
struct Segment {
  std::string name;
  int joint = -1;                        ///< joint that carries it
  double mass = 0.0;                     ///< (kg)
  Vector3 com = Vector3::Zero();         ///< centre of mass in the joint frame (m)
  Matrix3 inertia = Matrix3::Zero();     ///< inertia about the CoM, joint-frame axes (kg·m²)
  double length = 0.0;                   ///< anatomical length used for scaling (m)
  Capsule capsule;                       ///< collision capsule, joint frame
};

/// A named frame rigidly attached to a joint (control frames: hands, feet, pelvis, head...).
struct Frame {
  std::string name;
  int joint = -1;   ///< joint whose frame carries it
  SE3 placement;    ///< pose in the joint frame
};

/// The kinematic model: a tree of joints with segments and frames. Read-only after building.
class Model {
 public:
  std::string name;
  int nq = 0;  ///< configuration size
  int nv = 0;  ///< velocity size (== nq)
  std::vector<Joint> joints;      ///< parents always come before children
  std::vector<Segment> segments;
  std::vector<Frame> frames;
  VectorX lower_limit;            ///< (nq) lower joint limits (rad; −inf where none)
  VectorX upper_limit;            ///< (nq) upper joint limits
  /// support[i]: joint indices from the root to joint i inclusive (the joints moving joint i).
  std::vector<std::vector<int>> support;

  /// Adds a joint under `parent` (−1 = world). \throws std::invalid_argument on a duplicate
  /// name, an unknown parent, a zero revolute axis, or a second free flyer / a free flyer not at the root.
  int addJoint(const std::string& name, JointType type, int parent, const SE3& placement,
               const Vector3& axis = Vector3::UnitZ());
  /// Adds a segment on a joint. \throws std::invalid_argument on a duplicate name, unknown joint,
  /// negative or non-finite mass, or a non-symmetric / non-finite inertia.
  int addSegment(const Segment& segment);
  /// Adds a frame on a joint. \throws std::invalid_argument on a duplicate name or unknown joint.
  int addFrame(const std::string& name, int joint, const SE3& placement);
  /// Sets limits of one coordinate (rad). \throws std::invalid_argument if lower > upper or NaN.
  void setLimits(int idx_q, double lower, double upper);

  /// Sets the swing/twist limits of ball joint `joint` (enabled). \throws std::invalid_argument
  /// naming the joint on a non-ball joint or when checkBallLimit() reports a problem.
  void setBallLimit(int joint, const BallLimit& limit);

  /// Index of a joint/segment/frame by name. \throws std::invalid_argument naming the missing
  /// item and listing what exists.
  int jointIndex(const std::string& name) const;
  int segmentIndex(const std::string& name) const;
  int frameIndex(const std::string& name) const;
  /// Same, returning −1 when absent.
  int findJoint(const std::string& name) const;
  int findSegment(const std::string& name) const;
  int findFrame(const std::string& name) const;

  /// Total mass (kg).
  double totalMass() const;
  /// The neutral configuration (all zeros: root at the world origin, anatomical posture).
  VectorX neutralConfiguration() const { return VectorX::Zero(nq); }
  /// Names of the nq coordinates, e.g. "knee_l", "hip_l.x", "root.px" (for logs and files).
  std::vector<std::string> coordinateNames() const;
  /// Parent of each velocity coordinate in the tree of coordinates (nv entries, −1 at the root): the
  /// previous coordinate of the same joint, else the last coordinate of the parent joint. Two
  /// coordinates move a common body only if one is an ancestor of the other (math::TreeCholesky).
  std::vector<int> velocityParents() const;
};

/// Every buffer the kinematic algorithms write. Build one per Model and thread.
struct Data {
  explicit Data(const Model& model);

  std::vector<SE3> liMi;     ///< (njoints) joint frame in its parent joint frame
  std::vector<SE3> oMi;      ///< (njoints) joint frame in the world
  std::vector<SE3> oMf;      ///< (nframes) frame poses in the world
  Matrix6X J;                ///< (6 × nv) joint Jacobian columns in the WORLD frame (spatial twists
                             ///< reduced at the world origin, thesis 1.22): V_{i/0(0)} = Σ_support J.col(k) v_k
  Vector3 com = Vector3::Zero();   ///< centre of mass of the whole body, world (m)
  Matrix3X Jcom;             ///< (3 × nv) CoM Jacobian, world frame (thesis 3.32–3.36)
  std::vector<Vector3> segment_com;  ///< (nsegments) segment CoMs in the world
  // scratch for the CoM Jacobian (subtree mass and first moment)
  std::vector<double> subtree_mass;     ///< (njoints)
  std::vector<Vector3> subtree_moment;  ///< (njoints) Σ m c over the subtree, world
  // inverse dynamics (dynamics.hpp): spatial quantities per joint, world frame, reduced at the origin
  std::vector<Vector6> joint_twist;   ///< (njoints) twist (ω, v) of each joint's body
  std::vector<Vector6> joint_accel;   ///< (njoints) spatial acceleration, gravity's −g included
  std::vector<Vector6> joint_wrench;  ///< (njoints) wrench (n, f) the parent applies through the joint
  VectorX tau;                        ///< (nv) joint torques / generalized forces, dual to v
};

}  // namespace mannequin::skeleton
