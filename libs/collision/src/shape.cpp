#include "mannequin/collision/shape.hpp"

#include <cmath>
#include <stdexcept>

namespace mannequin::collision {

const char* toString(ShapeType type) {
  switch (type) {
    case ShapeType::kPlane: return "plane";
    case ShapeType::kMesh: return "mesh";
    case ShapeType::kBox: return "box";
    case ShapeType::kCylinder: return "cylinder";
    case ShapeType::kCapsule: return "capsule";
    case ShapeType::kSphere: return "sphere";
  }
  return "?";
}

namespace {
void checkLength(double v, const char* field, bool strictly_positive) {
  if (!std::isfinite(v) || v < 0.0 || (strictly_positive && v == 0.0))
    throw std::invalid_argument(std::string(field) + " must be finite and " +
                                (strictly_positive ? "> 0" : ">= 0") + " (got " + std::to_string(v) + ")");
}
}  // namespace

Shape Shape::sphere(double radius) {
  checkLength(radius, "radius", true);
  Shape s;
  s.type = ShapeType::kSphere;
  s.radius = radius;
  return s;
}

Shape Shape::capsule(double radius, double length) {
  checkLength(radius, "radius", true);
  checkLength(length, "length", false);
  Shape s;
  s.type = ShapeType::kCapsule;
  s.radius = radius;
  s.length = length;
  return s;
}

Shape Shape::box(const Vector3& size) {
  checkLength(size.x(), "size[0]", true);
  checkLength(size.y(), "size[1]", true);
  checkLength(size.z(), "size[2]", true);
  Shape s;
  s.type = ShapeType::kBox;
  s.size = size;
  return s;
}

Shape Shape::cylinder(double radius, double length) {
  checkLength(radius, "radius", true);
  checkLength(length, "length", true);
  Shape s;
  s.type = ShapeType::kCylinder;
  s.radius = radius;
  s.length = length;
  return s;
}

Shape Shape::plane(const Vector3& normal, double offset) {
  if (!normal.allFinite() || normal.norm() < 1e-12)
    throw std::invalid_argument("normal must be finite and non-zero");
  if (!std::isfinite(offset)) throw std::invalid_argument("offset must be finite");
  Shape s;
  s.type = ShapeType::kPlane;
  s.normal = normal.normalized();
  s.offset = offset;
  return s;
}

Shape Shape::fromMesh(std::shared_ptr<const TriangleMesh> mesh, std::string source) {
  if (!mesh || mesh->triangles.empty()) throw std::invalid_argument("mesh has no triangle");
  Shape s;
  s.type = ShapeType::kMesh;
  s.mesh = std::move(mesh);
  s.source = std::move(source);
  return s;
}

}  // namespace mannequin::collision
