#include "mannequin/collision/scene.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "mannequin/collision/world.hpp"
#include "test_util.hpp"

using namespace mannequin::collision;
using mannequin::core::ConfigError;

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
  const auto expectError = [](const std::string& yaml, const std::string& what) {
    const std::string e = sceneError(yaml);
    EXPECT_NE(e.find(what), std::string::npos) << "yaml:\n" << yaml << "got: " << e;
  };
  expectError("bodies:\n  - name: a\n    shapes:\n      - {type: cone, radius: 1}\n",
              "test.yaml:4: field 'bodies[0].shapes[0].type': unknown shape type 'cone'");
  expectError("bodies:\n  - name: a\n    shapes:\n      - type: sphere\n        radius: -0.2\n",
              "test.yaml:5: field 'bodies[0].shapes[0].radius': must be > 0, got -0.2");
  expectError("bodies:\n  - name: a\n    shapes: [{type: capsule, radius: 0.1, length: -1}]\n",
              "test.yaml:3: field 'bodies[0].shapes[0].length': must be >= 0, got -1");
  expectError("bodies:\n  - name: a\n    shapes: [{type: capsule, radius: 0.1}]\n",
              "test.yaml:3: field 'bodies[0].shapes[0]': missing key 'length' (required for a capsule)");
  expectError("bodies:\n  - name: a\n    shapes: [{radius: 0.1}]\n", "field 'bodies[0].shapes[0]': missing key 'type'");
  expectError("bodies:\n  - name: a\n    shapes: [{type: box, size: [1, 2]}]\n",
              "test.yaml:3: field 'bodies[0].shapes[0].size': expected [x, y, z], got 2 values");
  expectError("bodies:\n  - name: a\n    shapes: [{type: box, size: [1, 0, 2]}]\n",
              "field 'bodies[0].shapes[0].size[1]': must be > 0, got 0");
  expectError("bodies:\n  - name: a\n    shapes: [{type: sphere, radius: .nan}]\n", "'.nan' is not a finite number");
  expectError("bodies:\n  - name: a\n    shapes: [{type: plane, normal: [0, 0, 0]}]\n",
              "field 'bodies[0].shapes[0].normal': must be non-zero");
  expectError("bodies:\n  - name: a\n    colour: red\n    shapes: [{type: sphere, radius: 1}]\n",
              "test.yaml:3: field 'bodies[0].colour': unknown key");
  expectError("bodies:\n  - name: a\n    pose: {position: [0, 0, 0], yaw: 3}\n    shapes: [{type: sphere, radius: 1}]\n",
              "test.yaml:3: field 'bodies[0].pose.yaw': unknown key (expected one of: position, rpy_deg)");
  expectError("bodies:\n  - name: a\n    shapes: [{type: sphere, radius: 1}]\n  - name: a\n    shapes: [{type: sphere, radius: 1}]\n",
              "test.yaml:4: field 'bodies[1].name': duplicate body 'a'");
  expectError("bodies:\n  - name: a/b\n    shape: {type: sphere, radius: 1}\n", "field 'bodies[0].name': must be non-empty without '/'");
  expectError("bodies:\n  - name: a\n    shape: {type: sphere, radius: 1}\n    shapes: []\n",
              "test.yaml:2: field 'bodies[0]': give either 'shape' or 'shapes', not both");
  expectError("bodies:\n  - name: a\n    shapes: []\n", "test.yaml:3: field 'bodies[0].shapes': expected a non-empty list of shapes");
  expectError("bodies:\n  - name: a\n", "test.yaml:2: field 'bodies[0]': missing key 'shapes'");
  expectError("bodies: [\n", "test.yaml:2: YAML syntax error");
  expectError("name: x\n", "test.yaml:1: field '<top>': missing required key 'bodies'");
  expectError("margin: -0.1\nbodies: []\n", "test.yaml:1: field 'margin': must be >= 0, got -0.1");
  try {
    loadScene("/nonexistent/scene.yaml");
    FAIL() << "no error for a missing scene file";
  } catch (const ConfigError& err) {
    EXPECT_EQ(std::string(err.what()).rfind("/nonexistent/scene.yaml:0: cannot read the file", 0), 0u) << err.what();
  }
}

TEST(Scene, MissingAndCorruptMeshFiles) {
  const std::string dir = test::tempDir("scene_mesh");
  std::string e = sceneError("bodies:\n  - name: a\n    shapes:\n      - {type: mesh, file: nothere.stl}\n", dir);
  EXPECT_NE(e.find("test.yaml:4: field 'bodies[0].shapes[0].file'"), std::string::npos) << e;
  EXPECT_NE(e.find(dir + "/nothere.stl: no such mesh file"), std::string::npos) << e;
  writeText(dir + "/garbage.stl", std::string(40, '\x01') + " this is not an STL file at all");
  e = sceneError("bodies:\n  - name: a\n    shapes:\n      - {type: mesh, file: garbage.stl}\n", dir);
  EXPECT_NE(e.find("field 'bodies[0].shapes[0].file'"), std::string::npos) << e;
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

// Dynamics of movable bodies (constraints::RigidObject): mass, inertia (default: solid bounding box), hinge.
TEST(Scene, MovableBodyDynamics) {
  const SceneSpec s = parseScene(
      "bodies:\n"
      "  - name: tray\n"
      "    movable: true\n"
      "    mass: 1.2\n"
      "    shapes: [{type: box, size: [0.4, 0.3, 0.02]}]\n"
      "  - name: ball\n"
      "    movable: true\n"
      "    mass: 0.45\n"
      "    inertia: [0.002, 0.002, 0.002]\n"
      "    time_constant: 0.1\n"
      "    shape: {type: sphere, radius: 0.11}\n"
      "  - name: door\n"
      "    movable: true\n"
      "    mass: 20\n"
      "    hinge: {axis: [0, 0, 2], point: [1, 0, 0], limits_deg: [-10, 90]}\n"
      "    shape: {type: box, size: [0.9, 0.04, 2.0], pose: {position: [0.45, 0, 0]}}\n"
      "  - name: kinematic\n"
      "    movable: true\n"
      "    shape: {type: sphere, radius: 0.1}\n",
      "test.yaml");
  ASSERT_EQ(s.bodies.size(), 4u);
  ASSERT_TRUE(s.bodies[0].dynamics);
  const BodyDynamics& tray = *s.bodies[0].dynamics;
  EXPECT_DOUBLE_EQ(tray.mass, 1.2);
  // solid box 0.4 × 0.3 × 0.02: Ixx = m (0.3² + 0.02²)/12 ...
  EXPECT_NEAR(tray.inertia.x(), 1.2 * (0.09 + 0.0004) / 12, 1e-12);
  EXPECT_NEAR(tray.inertia.y(), 1.2 * (0.16 + 0.0004) / 12, 1e-12);
  EXPECT_NEAR(tray.inertia.z(), 1.2 * (0.16 + 0.09) / 12, 1e-12);
  EXPECT_LT(tray.time_constant, 0.0);  // the simulation's default
  EXPECT_FALSE(tray.hinge);
  const BodyDynamics& ball = *s.bodies[1].dynamics;
  EXPECT_DOUBLE_EQ(ball.inertia.z(), 0.002);
  EXPECT_DOUBLE_EQ(ball.time_constant, 0.1);
  const BodyDynamics& door = *s.bodies[2].dynamics;
  ASSERT_TRUE(door.hinge);
  EXPECT_TRUE(door.hinge->axis.isApprox(mannequin::math::Vector3::UnitZ()));
  EXPECT_TRUE(door.hinge->point.isApprox(mannequin::math::Vector3(1, 0, 0)));
  EXPECT_NEAR(door.hinge->lower, -10 * M_PI / 180, 1e-15);
  EXPECT_NEAR(door.hinge->upper, 90 * M_PI / 180, 1e-15);
  // the bounding box follows the shape's pose in the body frame: x ∈ [0, 0.9]
  EXPECT_NEAR(door.inertia.z(), 20 * (0.81 + 0.0016) / 12, 1e-12);
  EXPECT_FALSE(s.bodies[3].dynamics);  // movable without mass: kinematic

  // shipped: the table's ball (Fig. 3.6) and tray, the door and the lever on their hinges
  const auto body = [](const SceneSpec& sc, const std::string& name) -> const BodySpec& {
    for (const BodySpec& b : sc.bodies)
      if (b.name == name) return b;
    throw std::runtime_error("no body " + name);
  };
  const SceneSpec table = loadScene(test::sourcePath("configs/scenes/table.yaml"));
  ASSERT_TRUE(body(table, "ball").dynamics);
  EXPECT_DOUBLE_EQ(body(table, "ball").dynamics->mass, 0.45);
  ASSERT_TRUE(body(table, "tray").dynamics);
  EXPECT_FALSE(body(table, "tool").dynamics);
  const SceneSpec dl = loadScene(test::sourcePath("configs/scenes/door_lever.yaml"));
  ASSERT_TRUE(body(dl, "door").dynamics && body(dl, "door").dynamics->hinge);
  EXPECT_NEAR(body(dl, "door").dynamics->hinge->upper, 100 * M_PI / 180, 1e-12);
  ASSERT_TRUE(body(dl, "lever").dynamics && body(dl, "lever").dynamics->hinge);
  EXPECT_NEAR(body(dl, "lever").dynamics->hinge->lower, -30 * M_PI / 180, 1e-12);
}

TEST(Scene, MovableBodyDynamicsErrors) {
  const auto expectError = [](const std::string& yaml, const std::string& what) {
    const std::string e = sceneError(yaml);
    EXPECT_NE(e.find(what), std::string::npos) << "yaml:\n" << yaml << "got: " << e;
  };
  const std::string head = "bodies:\n  - name: a\n    movable: true\n    shape: {type: sphere, radius: 0.1}\n";
  expectError(head + "    mass: -1\n", "test.yaml:5: field 'bodies[0].mass': must be > 0, got -1");
  expectError(head + "    mass: 0\n", "test.yaml:5: field 'bodies[0].mass': must be > 0, got 0");
  expectError("bodies:\n  - name: a\n    shape: {type: sphere, radius: 0.1}\n    mass: 1\n",
              "test.yaml:4: field 'bodies[0].mass': only a movable body has dynamics");
  expectError(head + "    inertia: [1, 1, 1]\n", "test.yaml:5: field 'bodies[0].inertia': needs the body's 'mass'");
  expectError(head + "    mass: 1\n    inertia: [1, 1]\n", "test.yaml:6: field 'bodies[0].inertia': expected [Ixx, Iyy, Izz]");
  expectError(head + "    mass: 1\n    inertia: [1, -1, 1]\n", "field 'bodies[0].inertia[1]': must be > 0, got -1");
  expectError(head + "    mass: 1\n    inertia: [1, 1, 3]\n", "test.yaml:6: field 'bodies[0].inertia': not the principal moments");
  expectError(head + "    mass: 1\n    time_constant: 0\n", "test.yaml:6: field 'bodies[0].time_constant': must be > 0");
  expectError(head + "    mass: 1\n    hinge: {point: [0, 0, 0]}\n", "test.yaml:6: field 'bodies[0].hinge': missing key 'axis'");
  expectError(head + "    mass: 1\n    hinge: {axis: [0, 0, 0]}\n", "test.yaml:6: field 'bodies[0].hinge.axis': must be non-zero");
  expectError(head + "    mass: 1\n    hinge: {axis: [0, 0, 1], limits_deg: [10, 20]}\n",
              "test.yaml:6: field 'bodies[0].hinge.limits_deg': the initial pose (angle 0) must lie within [lower, upper]");
  expectError(head + "    mass: 1\n    hinge: {axis: [0, 0, 1], limits_deg: [0, 0]}\n",
              "field 'bodies[0].hinge.limits_deg': expected lower < upper");
  expectError(head + "    mass: 1\n    hinge: {axis: [0, 0, 1], spring: 3}\n", "field 'bodies[0].hinge.spring': unknown key");
  expectError("bodies:\n  - name: a\n    movable: true\n    shape: {type: plane}\n    mass: 1\n",
              "test.yaml:5: field 'bodies[0].mass': cannot default 'inertia' from the shapes");
}
