#include "mannequin/collision/scene.hpp"

#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>
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

// `mass`, `inertia`, `hinge`, `time_constant` of a movable body (after its shapes).
void readDynamics(const ConfigNode& b, BodySpec& body) {
  const auto mass = b.find("mass");
  for (const char* key : {"inertia", "hinge", "time_constant"})
    if (!mass && b.has(key)) b[key].fail("needs the body's 'mass' (kg)");
  if (!mass) return;
  if (!body.movable) mass->fail("only a movable body has dynamics (add 'movable: true')");
  BodyDynamics d;
  d.mass = mass->positive();
  if (const auto in = b.find("inertia")) {
    const auto v = in->items();
    if (v.size() != 3) in->fail("expected [Ixx, Iyy, Izz] (kg·m², body frame), got " + std::to_string(v.size()) + " values");
    d.inertia = Vector3(v[0].positive(), v[1].positive(), v[2].positive());
    // principal moments of a real body: each at most the sum of the other two
    for (int i = 0; i < 3; ++i)
      if (d.inertia[i] > d.inertia[(i + 1) % 3] + d.inertia[(i + 2) % 3] + 1e-12)
        in->fail("not the principal moments of a body: I" + std::string(1, "xyz"[i]) + std::string(1, "xyz"[i]) +
                 " exceeds the sum of the other two");
  } else {
    Vector3 lo, hi;
    try {
      bodyBounds(body, lo, hi);
    } catch (const std::invalid_argument& e) {
      mass->fail(std::string("cannot default 'inertia' from the shapes: ") + e.what() + "; give 'inertia'");
    }
    const Vector3 s = (hi - lo).cwiseMax(1e-6);  // a flat shape still gets a tiny thickness
    d.inertia = d.mass / 12.0 *
                Vector3(s.y() * s.y() + s.z() * s.z(), s.x() * s.x() + s.z() * s.z(), s.x() * s.x() + s.y() * s.y());
  }
  if (const auto t = b.find("time_constant")) d.time_constant = t->positive();
  if (const auto h = b.find("hinge")) {
    h->allowOnly({"axis", "point", "limits_deg"});
    HingeSpec hinge;
    if (!h->has("axis")) h->fail("missing key 'axis' ([x, y, z], world frame)");
    const ConfigNode axis = (*h)["axis"];
    const Vector3 a = axis.vec3();
    if (a.norm() < 1e-9) axis.fail("must be non-zero");
    hinge.axis = a.normalized();
    if (const auto p = h->find("point")) hinge.point = p->vec3();
    if (const auto l = h->find("limits_deg")) {
      const auto v = l->items();
      if (v.size() != 2) l->fail("expected [lower, upper] (degrees), got " + std::to_string(v.size()) + " values");
      const double deg = M_PI / 180.0;
      hinge.lower = v[0].numOrInfinity() * deg;
      hinge.upper = v[1].numOrInfinity() * deg;
      if (!(hinge.lower <= 0.0 && 0.0 <= hinge.upper))
        l->fail("the initial pose (angle 0) must lie within [lower, upper]");
      if (!(hinge.lower < hinge.upper)) l->fail("expected lower < upper");
    }
    d.hinge = hinge;
  }
  body.dynamics = d;
}

SceneSpec readScene(const ConfigNode& root, const std::string& base_dir) {
  root.allowOnly({"name", "activation_distance", "margin", "bodies", "default_material", "friction"});
  Reader reader{base_dir, {}};
  SceneSpec scene;
  scene.source = root.file();
  scene.name = root.get("name", scene.name);
  if (const auto a = root.find("activation_distance")) scene.activation_distance = a->nonNegative();
  if (const auto m = root.find("margin")) scene.margin = m->nonNegative();
  scene.default_material = root.get("default_material", scene.default_material);
  if (scene.default_material.empty()) root["default_material"].fail("must be non-empty");
  if (const auto f = root.find("friction")) {
    f->allowOnly({"default", "pairs"});
    if (const auto d = f->find("default")) scene.default_mu = d->nonNegative();
    if (const auto pairs = f->find("pairs"))
      for (const ConfigNode& p : pairs->items()) {
        p.allowOnly({"a", "b", "mu"});
        FrictionPair fp{p["a"].str(), p["b"].str(), p["mu"].nonNegative()};
        if (fp.a.empty() || fp.b.empty()) p.fail("materials 'a' and 'b' must be non-empty");
        for (const FrictionPair& q : scene.friction)
          if ((q.a == fp.a && q.b == fp.b) || (q.a == fp.b && q.b == fp.a))
            p.fail("pair (" + fp.a + ", " + fp.b + ") given twice");
        scene.friction.push_back(fp);
      }
  }
  std::set<std::string> names;
  for (const ConfigNode& b : root["bodies"].items()) {
    b.allowOnly({"name", "pose", "movable", "margin", "material", "shapes", "shape", "mass", "inertia", "hinge",
                 "time_constant"});
    BodySpec body;
    const ConfigNode name = b["name"];
    body.name = name.str();
    if (body.name.empty() || body.name.find('/') != std::string::npos) name.fail("must be non-empty without '/'");
    if (!names.insert(body.name).second) name.fail("duplicate body '" + body.name + "'");
    if (const auto p = b.find("pose")) body.pose = pose(*p);
    body.movable = b.get("movable", body.movable);
    if (const auto m = b.find("margin")) body.margin = m->nonNegative();
    body.material = b.get("material", scene.default_material);
    if (body.material.empty()) b["material"].fail("must be non-empty");
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
    readDynamics(b, body);
    scene.bodies.push_back(std::move(body));
  }
  return scene;
}

}  // namespace

void bodyBounds(const BodySpec& body, Vector3& lo, Vector3& hi) {
  lo = Vector3::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (const PlacedShape& ps : body.shapes) {
    const Shape& s = ps.shape;
    Vector3 slo, shi;  // bounds in the shape frame
    switch (s.type) {
      case ShapeType::kPlane:
        throw std::invalid_argument("body '" + body.name + "' has a plane (unbounded)");
      case ShapeType::kSphere:
        shi = Vector3::Constant(s.radius);
        break;
      case ShapeType::kBox:
        shi = s.size / 2;
        break;
      case ShapeType::kCapsule:
        shi = Vector3(s.radius, s.radius, s.radius + s.length / 2);
        break;
      case ShapeType::kCylinder:
        shi = Vector3(s.radius, s.radius, s.length / 2);
        break;
      case ShapeType::kMesh:
        s.mesh->bounds(slo, shi);
        break;
    }
    if (s.type != ShapeType::kMesh) slo = -shi;
    // the eight corners in the body frame
    for (int c = 0; c < 8; ++c) {
      const Vector3 corner((c & 1) ? shi.x() : slo.x(), (c & 2) ? shi.y() : slo.y(), (c & 4) ? shi.z() : slo.z());
      const Vector3 x = ps.pose.act(corner);
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
  }
  if (body.shapes.empty()) lo = hi = Vector3::Zero();
}

SceneSpec parseScene(const std::string& yaml_text, const std::string& source, const std::string& base_dir) {
  return readScene(ConfigNode::parse(yaml_text, source), base_dir);
}

SceneSpec loadScene(const std::string& path) {
  const auto dir = std::filesystem::path(path).parent_path();
  return readScene(ConfigNode::load(path), dir.empty() ? "." : dir.string());
}

}  // namespace mannequin::collision
