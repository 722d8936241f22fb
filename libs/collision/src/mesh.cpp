#include "mannequin/collision/mesh.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace mannequin::collision {

void TriangleMesh::bounds(Vector3& lo, Vector3& hi) const {
  if (vertices.empty()) {
    lo = hi = Vector3::Zero();
    return;
  }
  lo = hi = vertices.front();
  for (const auto& v : vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
}

int TriangleMesh::dropDegenerate(double min_area) {
  const auto before = triangles.size();
  std::erase_if(triangles, [&](const std::array<int, 3>& t) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
    const Vector3 n = (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
    return 0.5 * n.norm() <= min_area;
  });
  return static_cast<int>(before - triangles.size());
}

void TriangleMesh::validate(const std::string& source) const {
  if (triangles.empty()) throw MeshError(source + ": the mesh has no triangle");
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (!vertices[i].allFinite())
      throw MeshError(source + ": vertex " + std::to_string(i) + " is not finite");
  const int n = static_cast<int>(vertices.size());
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (int k : triangles[i])
      if (k < 0 || k >= n)
        throw MeshError(source + ": triangle " + std::to_string(i) + " has vertex index " +
                        std::to_string(k) + " out of range [0, " + std::to_string(n) + ")");
}

TriangleMesh loadMesh(const std::string& path, double scale) {
  if (!std::isfinite(scale) || scale <= 0.0)
    throw MeshError(path + ": scale must be finite and > 0 (got " + std::to_string(scale) + ")");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw MeshError(path + ": no such mesh file");
  Assimp::Importer importer;
  // keep only triangles: points and lines are dropped by the importer
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                aiProcess_SortByPType);
  if (scene == nullptr)
    throw MeshError(path + ": cannot read mesh: " + std::string(importer.GetErrorString()));
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    if (am == nullptr || !(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    const int base = static_cast<int>(mesh.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      mesh.vertices.emplace_back(scale * p.x, scale * p.y, scale * p.z);
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.triangles.push_back({base + static_cast<int>(face.mIndices[0]),
                                base + static_cast<int>(face.mIndices[1]),
                                base + static_cast<int>(face.mIndices[2])});
    }
  }
  mesh.validate(path);
  mesh.dropDegenerate();
  if (mesh.triangles.empty()) throw MeshError(path + ": every triangle is degenerate");
  return mesh;
}

void writeObj(const TriangleMesh& mesh, const std::string& path, const std::string& comment) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw MeshError(path + ": cannot write");
  if (!comment.empty()) std::fprintf(f, "# %s\n", comment.c_str());
  std::fprintf(f, "# %zu vertices, %zu triangles, metres\n", mesh.vertices.size(), mesh.triangles.size());
  for (const auto& v : mesh.vertices) std::fprintf(f, "v %.6f %.6f %.6f\n", v.x(), v.y(), v.z());
  for (const auto& t : mesh.triangles) std::fprintf(f, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
  if (std::fclose(f) != 0) throw MeshError(path + ": cannot write");
}

void writeStl(const TriangleMesh& mesh, const std::string& path, const std::string& header) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw MeshError(path + ": cannot write");
  char head[80] = {};
  // an STL binary header must not start with "solid" (readers would take it for ASCII)
  std::snprintf(head, sizeof head, "%s", header.empty() ? "mannequin mesh" : header.c_str());
  out.write(head, 80);
  const auto n = static_cast<std::uint32_t>(mesh.triangles.size());
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : mesh.triangles) {
    const Vector3& a = mesh.vertices[t[0]];
    const Vector3& b = mesh.vertices[t[1]];
    const Vector3& c = mesh.vertices[t[2]];
    Vector3 nrm = (b - a).cross(c - a);
    if (nrm.norm() > 0) nrm.normalize();
    float buf[12];
    const Vector3* vs[4] = {&nrm, &a, &b, &c};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) buf[3 * k + j] = static_cast<float>((*vs[k])[j]);
    out.write(reinterpret_cast<const char*>(buf), sizeof buf);
    const std::uint16_t attr = 0;
    out.write(reinterpret_cast<const char*>(&attr), 2);
  }
  if (!out) throw MeshError(path + ": cannot write");
}

}  // namespace mannequin::collision
