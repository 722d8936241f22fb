#include "mannequin/collision/scene.hpp"

#include <filesystem>
#include <map>
#include <memory>
#include <set>

namespace mannequin::collision {

math::Matrix3 rpy(double roll, double pitch, double yaw) {
  using Eigen::AngleAxisd;
  return (AngleAxisd(yaw, Vector3::UnitZ()) * AngleAxisd(pitch, Vector3::UnitY()) *
          AngleAxisd(roll, Vector3::UnitX()))
      .toRotationMatrix();
}

namespace {

using core::ConfigNode;

// a length in m: >= 0, or > 0 if `strictly_positive`
double length(const ConfigNode& n, bool strictly_positive) { return strictly_positive ? n.positive() : n.nonNegative(); }

// {position: [x, y, z] (m), rpy_deg: [roll, pitch, yaw]}
SE3 pose(const ConfigNode& n) {
  n.allowOnly({"position", "rpy_deg"});
  SE3 H;
  if (const auto p = n.find("position")) H.p = p->vec3();
  if (const auto r = n.find("rpy_deg")) H.R = r->rpyDeg();
  return H;
}

struct Reader {
  const std::string& base_dir;
  std::map<std::string, std::shared_ptr<const TriangleMesh>> meshes;  // same file + scale: loaded once

  PlacedShape shape(const ConfigNode& n) {
    n.allowOnly({"type", "radius", "length", "size", "normal", "offset", "file", "scale", "pose"});
    if (!n.has("type")) n.fail("missing key 'type' (one of plane, box, sphere, cylinder, capsule, mesh)");
    const ConfigNode type_node = n["type"];
    const std::string type = type_node.str();
    const auto need = [&](const char* key) {
      if (!n.has(key)) n.fail(std::string("missing key '") + key + "' (required for a " + type + ")");
      return n[key];
    };
    PlacedShape ps;
    if (const auto p = n.find("pose")) ps.pose = pose(*p);
    if (type == "sphere") {
      ps.shape = Shape::sphere(length(need("radius"), true));
    } else if (type == "capsule") {
      ps.shape = Shape::capsule(length(need("radius"), true), length(need("length"), false));
    } else if (type == "cylinder") {
      ps.shape = Shape::cylinder(length(need("radius"), true), length(need("length"), true));
    } else if (type == "box") {
      const auto size = need("size").items();
      if (size.size() != 3) n["size"].fail("expected [x, y, z], got " + std::to_string(size.size()) + " values");
      ps.shape = Shape::box(Vector3(size[0].positive(), size[1].positive(), size[2].positive()));
    } else if (type == "plane") {
      const auto normal = n.find("normal");
      const Vector3 v = normal ? normal->vec3() : Vector3::UnitZ();
      if (v.norm() < 1e-9) normal->fail("must be non-zero");
      ps.shape = Shape::plane(v, n.get("offset", 0.0));
    } else if (type == "mesh") {
      const ConfigNode file_node = need("file");
      const std::string file = file_node.str();
      const double scale = n.has("scale") ? length(n["scale"], true) : 1.0;
      std::filesystem::path p(file);
      if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
      const std::string path = p.lexically_normal().string();
      const std::string key = path + "|" + std::to_string(scale);
      auto it = meshes.find(key);
      if (it == meshes.end()) {
        try {
          it = meshes.emplace(key, std::make_shared<const TriangleMesh>(loadMesh(path, scale))).first;
        } catch (const MeshError& e) {
          file_node.fail(e.what());
        }
      }
      ps.shape = Shape::fromMesh(it->second, path);
    } else {
      type_node.fail("unknown shape type '" + type + "' (expected plane, box, sphere, cylinder, capsule or mesh)");
    }
    return ps;
  }
};

SceneSpec readScene(const ConfigNode& root, const std::string& base_dir) {
  root.allowOnly({"name", "activation_distance", "margin", "bodies"});
  Reader reader{base_dir, {}};
  SceneSpec scene;
  scene.source = root.file();
  scene.name = root.get("name", scene.name);
  if (const auto a = root.find("activation_distance")) scene.activation_distance = a->nonNegative();
  if (const auto m = root.find("margin")) scene.margin = m->nonNegative();
  std::set<std::string> names;
  for (const ConfigNode& b : root["bodies"].items()) {
    b.allowOnly({"name", "pose", "movable", "margin", "shapes", "shape"});
    BodySpec body;
    const ConfigNode name = b["name"];
    body.name = name.str();
    if (body.name.empty() || body.name.find('/') != std::string::npos) name.fail("must be non-empty without '/'");
    if (!names.insert(body.name).second) name.fail("duplicate body '" + body.name + "'");
    if (const auto p = b.find("pose")) body.pose = pose(*p);
    body.movable = b.get("movable", body.movable);
    if (const auto m = b.find("margin")) body.margin = m->nonNegative();
    const auto one = b.find("shape"), list = b.find("shapes");
    if (one && list) b.fail("give either 'shape' or 'shapes', not both");
    if (one) {
      body.shapes.push_back(reader.shape(*one));
    } else if (list) {
      for (const ConfigNode& s : list->items()) body.shapes.push_back(reader.shape(s));
      if (body.shapes.empty()) list->fail("expected a non-empty list of shapes");
    } else {
      b.fail("missing key 'shapes' (a non-empty list of shapes) or 'shape'");
    }
    scene.bodies.push_back(std::move(body));
  }
  return scene;
}

}  // namespace

SceneSpec parseScene(const std::string& yaml_text, const std::string& source, const std::string& base_dir) {
  return readScene(ConfigNode::parse(yaml_text, source), base_dir);
}

SceneSpec loadScene(const std::string& path) {
  const auto dir = std::filesystem::path(path).parent_path();
  return readScene(ConfigNode::load(path), dir.empty() ? "." : dir.string());
}

}  // namespace mannequin::collision
