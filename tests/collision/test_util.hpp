#pragma once
// Helpers shared by the collision tests.
#include <cstdlib>
#include <filesystem>
#include <string>

#include "mannequin/collision/world.hpp"

namespace mannequin::collision::test {

inline std::string sourcePath(const std::string& rel) {
  const char* root = std::getenv("MANNEQUIN_SOURCE_DIR");
  return std::string(root ? root : ".") + "/" + rel;
}

/// A fresh temporary directory for files written by a test.
inline std::string tempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("mannequin_collision_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

/// Axis-aligned unit-cube-like box mesh [-h, h]³ (12 triangles, outward winding).
inline TriangleMesh boxMesh(double h) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h);
  const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

/// World position of a contact's witness point on body a / b.
inline Vector3 worldA(const CollisionWorld& w, const Contact& c) { return w.bodyPose(c.body_a).act(c.point_a); }
inline Vector3 worldB(const CollisionWorld& w, const Contact& c) { return w.bodyPose(c.body_b).act(c.point_b); }

}  // namespace mannequin::collision::test
