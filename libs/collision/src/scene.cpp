#include "mannequin/collision/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace mannequin::collision {

math::Matrix3 rpy(double roll, double pitch, double yaw) {
  using Eigen::AngleAxisd;
  return (AngleAxisd(yaw, Vector3::UnitZ()) * AngleAxisd(pitch, Vector3::UnitY()) *
          AngleAxisd(roll, Vector3::UnitX()))
      .toRotationMatrix();
}

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct Ctx {
  const std::string& source;
  const std::string& base_dir;
  std::map<std::string, std::shared_ptr<const TriangleMesh>> meshes;  // same file + scale: loaded once

  [[noreturn]] void fail(const YAML::Node& node, const std::string& field, const std::string& msg) const {
    const int line = node.Mark().line >= 0 ? node.Mark().line + 1 : 0;
    throw ConfigError(source + ":" + std::to_string(line) + ": " + field + ": " + msg);
  }

  void checkKeys(const YAML::Node& node, const std::string& field, std::initializer_list<const char*> keys) const {
    if (!node.IsMap()) fail(node, field, "expected a map");
    for (const auto& kv : node) {
      const std::string key = kv.first.as<std::string>();
      bool ok = false;
      for (const char* k : keys) ok = ok || key == k;
      if (!ok) {
        std::string list;
        for (const char* k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
        fail(kv.first, field.empty() ? key : field + "." + key, "unknown key (expected one of: " + list + ")");
      }
    }
  }

  double number(const YAML::Node& node, const std::string& field) const {
    double v = 0.0;
    try {
      v = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, field, "expected a number");
    }
    if (!std::isfinite(v)) fail(node, field, "must be finite");
    return v;
  }

  double length(const YAML::Node& node, const std::string& field, bool strictly_positive) const {
    const double v = number(node, field);
    if (v < 0.0) fail(node, field, "must be >= 0 (got " + node.as<std::string>() + ")");
    if (strictly_positive && v == 0.0) fail(node, field, "must be > 0");
    return v;
  }

  Vector3 vec3(const YAML::Node& node, const std::string& field) const {
    if (!node.IsSequence() || node.size() != 3) fail(node, field, "expected a list of 3 numbers");
    return {number(node[0], field + "[0]"), number(node[1], field + "[1]"), number(node[2], field + "[2]")};
  }

  bool boolean(const YAML::Node& node, const std::string& field) const {
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
      fail(node, field, "expected true or false");
    }
  }

  std::string text(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected a string");
    return node.as<std::string>();
  }

  SE3 pose(const YAML::Node& node, const std::string& field) const {
    checkKeys(node, field, {"position", "rpy_deg"});
    SE3 H;
    if (node["position"]) H.p = vec3(node["position"], field + ".position");
    if (node["rpy_deg"]) {
      const Vector3 a = vec3(node["rpy_deg"], field + ".rpy_deg") * kDeg;
      H.R = rpy(a.x(), a.y(), a.z());
    }
    return H;
  }

  PlacedShape shape(const YAML::Node& node, const std::string& field) {
    checkKeys(node, field, {"type", "radius", "length", "size", "normal", "offset", "file", "scale", "pose"});
    if (!node["type"]) fail(node, field + ".type", "missing (one of plane, box, sphere, cylinder, capsule, mesh)");
    const std::string type = text(node["type"], field + ".type");
    auto need = [&](const char* key) -> YAML::Node {
      if (!node[key]) fail(node, field + "." + key, std::string("missing (required for a ") + type + ")");
      return node[key];
    };
    PlacedShape ps;
    if (node["pose"]) ps.pose = pose(node["pose"], field + ".pose");
    if (type == "sphere") {
      ps.shape = Shape::sphere(length(need("radius"), field + ".radius", true));
    } else if (type == "capsule") {
      ps.shape = Shape::capsule(length(need("radius"), field + ".radius", true),
                                length(need("length"), field + ".length", false));
    } else if (type == "cylinder") {
      ps.shape = Shape::cylinder(length(need("radius"), field + ".radius", true),
                                 length(need("length"), field + ".length", true));
    } else if (type == "box") {
      const Vector3 size = vec3(need("size"), field + ".size");
      for (int k = 0; k < 3; ++k)
        if (size[k] <= 0.0) fail(node["size"], field + ".size[" + std::to_string(k) + "]", "must be > 0");
      ps.shape = Shape::box(size);
    } else if (type == "plane") {
      const Vector3 n = node["normal"] ? vec3(node["normal"], field + ".normal") : Vector3::UnitZ();
      if (n.norm() < 1e-9) fail(node["normal"], field + ".normal", "must be non-zero");
      ps.shape = Shape::plane(n, node["offset"] ? number(node["offset"], field + ".offset") : 0.0);
    } else if (type == "mesh") {
      const std::string file = text(need("file"), field + ".file");
      const double scale = node["scale"] ? length(node["scale"], field + ".scale", true) : 1.0;
      std::filesystem::path p(file);
      if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
      const std::string path = p.lexically_normal().string();
      const std::string key = path + "|" + std::to_string(scale);
      auto it = meshes.find(key);
      if (it == meshes.end()) {
        try {
          it = meshes.emplace(key, std::make_shared<const TriangleMesh>(loadMesh(path, scale))).first;
        } catch (const MeshError& e) {
          fail(node["file"], field + ".file", e.what());
        }
      }
      ps.shape = Shape::fromMesh(it->second, path);
    } else {
      fail(node["type"], field + ".type",
           "unknown shape type '" + type + "' (expected plane, box, sphere, cylinder, capsule or mesh)");
    }
    return ps;
  }
};

}  // namespace

SceneSpec parseScene(const std::string& yaml_text, const std::string& source, const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
  Ctx ctx{source, base_dir, {}};
  if (!root.IsMap()) throw ConfigError(source + ":1: a scene file is a map with 'bodies'");
  ctx.checkKeys(root, "", {"name", "activation_distance", "margin", "bodies"});
  SceneSpec scene;
  scene.source = source;
  if (root["name"]) scene.name = ctx.text(root["name"], "name");
  if (root["activation_distance"])
    scene.activation_distance = ctx.length(root["activation_distance"], "activation_distance", false);
  if (root["margin"]) scene.margin = ctx.length(root["margin"], "margin", false);
  const YAML::Node bodies = root["bodies"];
  if (!bodies || !bodies.IsSequence()) throw ConfigError(source + ":1: bodies: missing list of bodies");
  std::set<std::string> names;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const YAML::Node b = bodies[i];
    const std::string field = "bodies[" + std::to_string(i) + "]";
    ctx.checkKeys(b, field, {"name", "pose", "movable", "margin", "shapes", "shape"});
    BodySpec body;
    if (!b["name"]) ctx.fail(b, field + ".name", "missing");
    body.name = ctx.text(b["name"], field + ".name");
    if (body.name.empty() || body.name.find('/') != std::string::npos)
      ctx.fail(b["name"], field + ".name", "must be non-empty without '/'");
    if (!names.insert(body.name).second) ctx.fail(b["name"], field + ".name", "duplicate body '" + body.name + "'");
    if (b["pose"]) body.pose = ctx.pose(b["pose"], field + ".pose");
    if (b["movable"]) body.movable = ctx.boolean(b["movable"], field + ".movable");
    if (b["margin"]) body.margin = ctx.length(b["margin"], field + ".margin", false);
    if (b["shape"] && b["shapes"]) ctx.fail(b, field, "give either 'shape' or 'shapes', not both");
    if (b["shape"]) {
      body.shapes.push_back(ctx.shape(b["shape"], field + ".shape"));
    } else if (b["shapes"] && b["shapes"].IsSequence() && b["shapes"].size() > 0) {
      for (std::size_t k = 0; k < b["shapes"].size(); ++k)
        body.shapes.push_back(ctx.shape(b["shapes"][k], field + ".shapes[" + std::to_string(k) + "]"));
    } else {
      ctx.fail(b, field + ".shapes", "missing (a non-empty list of shapes)");
    }
    scene.bodies.push_back(std::move(body));
  }
  return scene;
}

SceneSpec loadScene(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ":0: cannot open scene file");
  std::stringstream ss;
  ss << in.rdbuf();
  const auto dir = std::filesystem::path(path).parent_path();
  return parseScene(ss.str(), path, dir.empty() ? "." : dir.string());
}

}  // namespace mannequin::collision
