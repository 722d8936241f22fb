#pragma once
/// \file mesh.hpp
/// \brief Triangle meshes: loading from files (OBJ, STL, PLY, glTF/GLB and the other formats of
/// assimp), writing OBJ/STL (for the shipped, generated meshes), and checking.
///
/// Coordinates are taken as they are in the file, multiplied by `scale` (CAD files in millimetres:
/// scale 0.001). Several meshes/nodes in one file are merged, node transforms applied.
/// A mesh is a surface (it need not be closed): distances to it are unsigned outside-in, see
/// docs/collision.md.
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "mannequin/math/types.hpp"

namespace mannequin::collision {

using math::Vector3;

/// A mesh error: the message starts with the file name ("PATH: ...").
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Indexed triangle mesh in its own frame (m).
struct TriangleMesh {
  std::vector<Vector3> vertices;
  std::vector<std::array<int, 3>> triangles;  ///< vertex indices, counter-clockwise seen from outside

  /// Axis-aligned bounds of the vertices (lo, hi); zero for an empty mesh.
  void bounds(Vector3& lo, Vector3& hi) const;
  /// Drops triangles with a repeated index or a zero area (returns how many were dropped).
  int dropDegenerate(double min_area = 1e-14);
  /// \throws MeshError (prefixed with `source`) on an out-of-range index, a non-finite vertex or no triangle.
  void validate(const std::string& source) const;
};

/// Loads a mesh file through assimp. \throws MeshError "PATH: ..." for a missing or unreadable
/// file, a format assimp cannot parse, a file without triangles, non-finite coordinates, or a
/// non-finite or non-positive scale.
TriangleMesh loadMesh(const std::string& path, double scale = 1.0);

/// Writes Wavefront OBJ (text) / binary STL. \throws MeshError when the file cannot be written.
void writeObj(const TriangleMesh& mesh, const std::string& path, const std::string& comment = "");
void writeStl(const TriangleMesh& mesh, const std::string& path, const std::string& header = "");

}  // namespace mannequin::collision
