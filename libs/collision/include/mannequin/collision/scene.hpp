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
///     shapes: [{type: sphere, radius: 0.11}]
/// ```
/// Poses: `position` (m) and `rpy_deg` (roll, pitch, yaw in degrees: R = Rz(yaw) Ry(pitch) Rx(roll)).
/// Relative mesh paths are resolved from the scene file's directory.
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

/// A rigid body of the scene.
struct BodySpec {
  std::string name;
  SE3 pose;                 ///< body frame in the world (initial pose for movable bodies)
  bool movable = false;     ///< objects (ball, tool, lever, door) move; the rest is static
  double margin = -1.0;     ///< m; < 0: the scene's default margin
  std::vector<PlacedShape> shapes;
};

struct SceneSpec {
  std::string name;
  std::string source;                 ///< file it was read from
  double activation_distance = -1.0;  ///< m; < 0: keep the World's
  double margin = 0.0;                ///< default body margin (m)
  std::vector<BodySpec> bodies;
};

/// Parses scene YAML; `source` names it in errors and `base_dir` resolves relative mesh paths.
/// \throws core::ConfigError "SOURCE:LINE: field 'a.b': message" (unknown shape type, negative radius,
/// missing or corrupt mesh file with the mesh's own message, duplicate body name, unknown key...).
SceneSpec parseScene(const std::string& yaml_text, const std::string& source,
                     const std::string& base_dir = ".");

/// Reads and parses a scene file. \throws core::ConfigError (unreadable file included, line 0).
SceneSpec loadScene(const std::string& path);

/// Roll-pitch-yaw (rad) to a rotation: Rz(yaw) Ry(pitch) Rx(roll).
math::Matrix3 rpy(double roll, double pitch, double yaw);

}  // namespace mannequin::collision
