#include "mannequin/collision/scene.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "mannequin/collision/world.hpp"
#include "test_util.hpp"

using namespace mannequin::collision;

namespace {

std::string sceneError(const std::string& yaml, const std::string& base = ".") {
  try {
    parseScene(yaml, "test.yaml", base);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace

TEST(Scene, ParsesPosesShapesAndDefaults) {
  const auto s = parseScene(R"(name: t
activation_distance: 0.03
margin: 0.001
bodies:
  - name: floor
    shape: {type: plane}
  - name: table
    pose: {position: [1, 0, 0], rpy_deg: [0, 0, 90]}
    margin: 0.002
    shapes:
      - {type: box, size: [1.2, 0.8, 0.04], pose: {position: [0, 0, 0.73]}}
      - {type: cylinder, radius: 0.03, length: 0.71}
  - name: ball
    movable: true
    shapes: [{type: sphere, radius: 0.11}]
)", "test.yaml");
  EXPECT_EQ(s.name, "t");
  EXPECT_DOUBLE_EQ(s.activation_distance, 0.03);
  ASSERT_EQ(s.bodies.size(), 3u);
  EXPECT_EQ(s.bodies[0].shapes[0].shape.type, ShapeType::kPlane);
  EXPECT_TRUE(s.bodies[0].shapes[0].shape.normal.isApprox(Vector3::UnitZ()));
  EXPECT_TRUE(s.bodies[1].pose.R.isApprox(rpy(0, 0, 3.14159265358979323846 / 2)));
  EXPECT_TRUE(s.bodies[1].pose.act(Vector3(1, 0, 0)).isApprox(Vector3(1, 1, 0)));
  EXPECT_EQ(s.bodies[1].shapes.size(), 2u);
  EXPECT_DOUBLE_EQ(s.bodies[1].margin, 0.002);
  EXPECT_LT(s.bodies[0].margin, 0.0);  // scene default applies
  EXPECT_TRUE(s.bodies[2].movable);
  CollisionWorld w;
  w.addScene(s);
  EXPECT_DOUBLE_EQ(w.activationDistance(), 0.03);
  EXPECT_DOUBLE_EQ(w.margin(w.findBody("scene/floor")), 0.001);
  EXPECT_EQ(w.bodyKind(w.findBody("scene/ball")), BodyKind::kMovable);
}

TEST(Scene, ErrorsNameFileLineAndField) {
  std::string e = sceneError("bodies:\n  - name: a\n    shapes:\n      - {type: cone, radius: 1}\n");
  EXPECT_NE(e.find("test.yaml:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("bodies[0].shapes[0].type"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown shape type 'cone'"), std::string::npos) << e;

  e = sceneError("bodies:\n  - name: a\n    shapes:\n      - type: sphere\n        radius: -0.2\n");
  EXPECT_NE(e.find("test.yaml:5:"), std::string::npos) << e;
  EXPECT_NE(e.find("bodies[0].shapes[0].radius"), std::string::npos) << e;
  EXPECT_NE(e.find(">= 0"), std::string::npos) << e;

  e = sceneError("bodies:\n  - name: a\n    shapes: [{type: capsule, radius: 0.1}]\n");
  EXPECT_NE(e.find("bodies[0].shapes[0].length"), std::string::npos) << e;
  e = sceneError("bodies:\n  - name: a\n    shapes: [{type: box, size: [1, 2]}]\n");
  EXPECT_NE(e.find("bodies[0].shapes[0].size"), std::string::npos) << e;
  e = sceneError("bodies:\n  - name: a\n    shapes: [{type: sphere, radius: .nan}]\n");
  EXPECT_NE(e.find("must be finite"), std::string::npos) << e;
  e = sceneError("bodies:\n  - name: a\n    colour: red\n    shapes: [{type: sphere, radius: 1}]\n");
  EXPECT_NE(e.find("test.yaml:3: bodies[0].colour: unknown key"), std::string::npos) << e;
  e = sceneError("bodies:\n  - name: a\n    shapes: [{type: sphere, radius: 1}]\n  - name: a\n    shapes: [{type: sphere, radius: 1}]\n");
  EXPECT_NE(e.find("duplicate body 'a'"), std::string::npos) << e;
  e = sceneError("bodies: [\n");
  EXPECT_NE(e.find("invalid YAML"), std::string::npos) << e;
  e = sceneError("name: x\n");
  EXPECT_NE(e.find("bodies"), std::string::npos) << e;
  try {
    loadScene("/nonexistent/scene.yaml");
    FAIL();
  } catch (const ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find("/nonexistent/scene.yaml:0: cannot open"), std::string::npos);
  }
}

TEST(Scene, MissingAndCorruptMeshFiles) {
  const std::string dir = test::tempDir("scene_mesh");
  std::string e = sceneError("bodies:\n  - name: a\n    shapes:\n      - {type: mesh, file: nothere.stl}\n", dir);
  EXPECT_NE(e.find("test.yaml:4: bodies[0].shapes[0].file"), std::string::npos) << e;
  EXPECT_NE(e.find(dir + "/nothere.stl: no such mesh file"), std::string::npos) << e;
  writeText(dir + "/garbage.stl", std::string(40, '\x01') + " this is not an STL file at all");
  e = sceneError("bodies:\n  - name: a\n    shapes:\n      - {type: mesh, file: garbage.stl}\n", dir);
  EXPECT_NE(e.find("bodies[0].shapes[0].file"), std::string::npos) << e;
  EXPECT_NE(e.find(dir + "/garbage.stl: "), std::string::npos) << e;
  writeText(dir + "/bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
  e = sceneError("bodies:\n  - name: a\n    shapes:\n      - {type: mesh, file: bad.obj}\n", dir);
  EXPECT_NE(e.find(dir + "/bad.obj: "), std::string::npos) << e;
  writeText(dir + "/empty.obj", "# nothing\n");
  EXPECT_THROW(loadMesh(dir + "/empty.obj"), MeshError);
  EXPECT_THROW(loadMesh(dir + "/garbage.stl", -1.0), MeshError);
}

TEST(Scene, MeshFormatsLoadTheSameGeometry) {
  const std::string dir = test::tempDir("formats");
  const TriangleMesh cube = test::boxMesh(0.5);
  writeObj(cube, dir + "/cube.obj");
  writeStl(cube, dir + "/cube.stl");
  // ASCII PLY
  std::string ply = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : cube.vertices) ply += std::to_string(v.x()) + " " + std::to_string(v.y()) + " " + std::to_string(v.z()) + "\n";
  for (const auto& t : cube.triangles) ply += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  writeText(dir + "/cube.ply", ply);
  // glTF 2.0 with the buffer embedded as a data URI (8 float vertices + 36 uint16 indices)
  std::string bin;
  for (const auto& v : cube.vertices)
    for (int k = 0; k < 3; ++k) {
      const float f = static_cast<float>(v[k]);
      bin.append(reinterpret_cast<const char*>(&f), 4);
    }
  for (const auto& t : cube.triangles)
    for (int k : t) {
      const auto i = static_cast<std::uint16_t>(k);
      bin.append(reinterpret_cast<const char*>(&i), 2);
    }
  static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string enc;
  for (std::size_t i = 0; i < bin.size(); i += 3) {
    unsigned v = static_cast<unsigned char>(bin[i]) << 16;
    if (i + 1 < bin.size()) v |= static_cast<unsigned char>(bin[i + 1]) << 8;
    if (i + 2 < bin.size()) v |= static_cast<unsigned char>(bin[i + 2]);
    enc += b64[(v >> 18) & 63];
    enc += b64[(v >> 12) & 63];
    enc += i + 1 < bin.size() ? b64[(v >> 6) & 63] : '=';
    enc += i + 2 < bin.size() ? b64[v & 63] : '=';
  }
  const std::string gltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
"buffers":[{"byteLength":168,"uri":"data:application/octet-stream;base64,)" + enc + R"("}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":96},{"buffer":0,"byteOffset":96,"byteLength":72}],
"accessors":[{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":[-0.5,-0.5,-0.5],"max":[0.5,0.5,0.5]},
{"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}]})";
  writeText(dir + "/cube.gltf", gltf);
  for (const char* f : {"cube.obj", "cube.stl", "cube.ply", "cube.gltf"}) {
    const TriangleMesh m = loadMesh(dir + "/" + f, 2.0);
    EXPECT_EQ(m.triangles.size(), 12u) << f;
    Vector3 lo, hi;
    m.bounds(lo, hi);
    EXPECT_TRUE(lo.isApprox(Vector3::Constant(-1.0), 1e-6)) << f;
    EXPECT_TRUE(hi.isApprox(Vector3::Constant(1.0), 1e-6)) << f;
  }
}

TEST(Scene, ShippedScenesLoadAndCockpitPanelIsDense) {
  const std::string dir = test::sourcePath("configs/scenes");
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    const SceneSpec s = loadScene(entry.path().string());
    EXPECT_FALSE(s.bodies.empty()) << entry.path();
    CollisionWorld w;
    w.addScene(s);
    ContactSet cs;
    w.query(0, cs);  // movable objects rest where the file puts them: nothing deeply inside
    for (const auto& c : cs.contacts) EXPECT_GT(c.distance, -1e-3) << entry.path() << " " << w.bodyName(c.body_a) << " " << w.bodyName(c.body_b);
    ++count;
  }
  EXPECT_GE(count, 5);
  const SceneSpec cockpit = loadScene(dir + "/cockpit.yaml");
  std::size_t tris = 0;
  for (const auto& b : cockpit.bodies)
    for (const auto& s : b.shapes)
      if (s.shape.type == ShapeType::kMesh) tris = std::max(tris, s.shape.mesh->triangles.size());
  EXPECT_GE(tris, 10000u);
}
