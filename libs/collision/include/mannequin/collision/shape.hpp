#pragma once
/// \file shape.hpp
/// \brief The collision shapes of bodies: primitives and triangle meshes, in the shape's frame.
///
/// Shape frames (the same as FCL's):
/// - kSphere: centred at the origin.
/// - kCapsule: segment from (0,0,−length/2) to (0,0,+length/2) swept by a sphere of `radius`
///   (the segment capsules of a mannequin are built from skeleton::Capsule{a, b, radius}).
/// - kBox: centred, edges along the axes, full sizes `size` (m).
/// - kCylinder: centred, axis z, full `length`.
/// - kPlane: the HALF-SPACE {x : normal·x ≤ offset} (solid below the plane; its surface is the plane).
/// - kMesh: a triangle surface (see mesh.hpp) in the shape frame.
#include <memory>
#include <string>

#include "mannequin/collision/mesh.hpp"

namespace mannequin::collision {

enum class ShapeType { kPlane, kMesh, kBox, kCylinder, kCapsule, kSphere };

/// Name as written in scene files ("plane", "mesh", "box", "cylinder", "capsule", "sphere").
const char* toString(ShapeType type);

/// One collision shape. Built with the named constructors, which check their arguments.
struct Shape {
  ShapeType type = ShapeType::kSphere;
  double radius = 0.0;                 ///< sphere, capsule, cylinder (m)
  double length = 0.0;                 ///< capsule (segment length), cylinder (m)
  Vector3 size = Vector3::Zero();      ///< box full sizes (m)
  Vector3 normal = Vector3::UnitZ();   ///< plane unit normal (shape frame)
  double offset = 0.0;                 ///< plane offset along the normal (m)
  std::shared_ptr<const TriangleMesh> mesh;  ///< mesh
  std::string source;                  ///< mesh file, for messages

  /// \throws std::invalid_argument on a negative or non-finite size (naming the field).
  static Shape sphere(double radius);
  static Shape capsule(double radius, double length);
  static Shape box(const Vector3& size);
  static Shape cylinder(double radius, double length);
  /// \throws std::invalid_argument on a zero or non-finite normal; the normal is normalised.
  static Shape plane(const Vector3& normal, double offset);
  /// \throws std::invalid_argument on a null or empty mesh.
  static Shape fromMesh(std::shared_ptr<const TriangleMesh> mesh, std::string source = "");
};

}  // namespace mannequin::collision
