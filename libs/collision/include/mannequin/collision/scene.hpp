#pragma once
/// \file scene.hpp
/// \brief Scene files (configs/scenes/*.yaml): named bodies made of shapes, static or movable.
///
/// Format (full reference in docs/collision.md):
/// ```yaml
/// name: table_scene
/// activation_distance: 0.02     # optional, m (pairs farther than this are not reported)
/// margin: 0.001                 # optional default margin of the scene's bodies, m
/// bodies:
///   - name: floor
///     shapes: [{type: plane, normal: [0, 0, 1], offset: 0}]
///   - name: table
///     pose: {position: [0.8, 0, 0], rpy_deg: [0, 0, 90]}
///     margin: 0.002
///     shapes:
///       - {type: box, size: [1.2, 0.8, 0.04], pose: {position: [0, 0, 0.73]}}
///   - name: panel
///     shapes: [{type: mesh, file: ../../data/meshes/cockpit_panel.obj, scale: 1.0}]
///   - name: ball
///     movable: true
///     material: rubber
///     shapes: [{type: sphere, radius: 0.11}]
///     mass: 0.45                # optional dynamics of a movable body (constraints::RigidObject)
///   - name: door
///     movable: true
///     mass: 20
///     hinge: {axis: [0, 0, 1], point: [2, 0.5, 0], limits_deg: [0, 100]}   # world frame
///     shapes: [{type: box, size: [0.04, 0.9, 2.0], pose: {position: [0, -0.45, 1.0]}}]
/// default_material: wood        # optional: material of bodies without one ("default")
/// friction:                     # optional: Coulomb μ per material pair (order free)
///   default: 0.5                #   pairs not listed (0: frictionless)
///   pairs: [{a: skin, b: wood, mu: 0.6}, {a: rubber, b: wood, mu: 0.8}]
/// ```
/// Mannequin segments have the material `skin` unless the sim config says otherwise.
/// Poses: `position` (m) and `rpy_deg` (roll, pitch, yaw in degrees: R = Rz(yaw) Ry(pitch) Rx(roll)).
/// Relative mesh paths are resolved from the scene file's directory.
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/collision/shape.hpp"
#include "mannequin/core/config.hpp"  // ConfigError
#include "mannequin/math/se3.hpp"

namespace mannequin::collision {

using math::SE3;

/// A shape placed in its body.
struct PlacedShape {
  Shape shape;
  SE3 pose;  ///< shape frame in the body frame
};

/// A hinge of a movable body: a rotation about a world axis through a world point (thesis 4.3.1: door,
/// throttle lever). The angle is 0 at the body's initial pose.
struct HingeSpec {
  math::Vector3 axis = math::Vector3::UnitZ();   ///< world, unit
  math::Vector3 point = math::Vector3::Zero();   ///< world, on the axis (m)
  double lower = -std::numeric_limits<double>::infinity();  ///< rad (−inf: no limit)
  double upper = std::numeric_limits<double>::infinity();   ///< rad (+inf: no limit)
};

/// First-order dynamics of a movable body (constraints::RigidObject). The body frame's origin is taken as the
/// centre of mass and its axes as the principal axes.
struct BodyDynamics {
  double mass = 0.0;                             ///< kg, > 0
  /// Principal moments [Ixx, Iyy, Izz] in the body frame (kg·m²). Default: a solid box of the shapes'
  /// bounding box in the body frame, I_xx = m (s_y² + s_z²)/12 ...
  math::Vector3 inertia = math::Vector3::Zero();
  double time_constant = -1.0;                   ///< s; < 0: the simulation's default
  std::optional<HingeSpec> hinge;                ///< none: a free rigid body
};

/// A rigid body of the scene.
struct BodySpec {
  std::string name;
  SE3 pose;                 ///< body frame in the world (initial pose for movable bodies)
  bool movable = false;     ///< objects (ball, tool, lever, door) move; the rest is static
  double margin = -1.0;     ///< m; < 0: the scene's default margin
  std::string material;     ///< friction material ("": the scene's default_material)
  std::vector<PlacedShape> shapes;
  /// Dynamics (`mass`, `inertia`, `hinge`, `time_constant`); only movable bodies have them. A movable
  /// body without dynamics is moved by setBodyPose() only (kinematic).
  std::optional<BodyDynamics> dynamics;
};

/// Coulomb coefficient of a pair of materials (order free).
struct FrictionPair {
  std::string a, b;
  double mu = 0.0;
};

struct SceneSpec {
  std::string name;
  std::string source;                 ///< file it was read from
  double activation_distance = -1.0;  ///< m; < 0: keep the World's
  double margin = 0.0;                ///< default body margin (m)
  std::string default_material = "default";  ///< material of bodies (and mannequin segments) without one
  double default_mu = 0.0;            ///< μ of a pair not listed in `friction` (0: frictionless)
  std::vector<FrictionPair> friction; ///< μ per material pair
  std::vector<BodySpec> bodies;
};

/// Parses scene YAML; `source` names it in errors and `base_dir` resolves relative mesh paths.
/// \throws core::ConfigError "SOURCE:LINE: field 'a.b': message" (unknown shape type, negative radius,
/// missing or corrupt mesh file with the mesh's own message, duplicate body name, unknown key...).
SceneSpec parseScene(const std::string& yaml_text, const std::string& source,
                     const std::string& base_dir = ".");

/// Reads and parses a scene file. \throws core::ConfigError (unreadable file included, line 0).
SceneSpec loadScene(const std::string& path);

/// Axis-aligned bounds (lo, hi) of a body's shapes in its body frame (a sphere, capsule or cylinder by
/// its bounding box). \throws std::invalid_argument for a plane (unbounded).
void bodyBounds(const BodySpec& body, math::Vector3& lo, math::Vector3& hi);

/// Roll-pitch-yaw (rad) to a rotation: Rz(yaw) Ry(pitch) Rx(roll).
math::Matrix3 rpy(double roll, double pitch, double yaw);

}  // namespace mannequin::collision
