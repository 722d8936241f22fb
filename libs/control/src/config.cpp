#include "mannequin/control/config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace mannequin::control {

namespace {

constexpr double kDeg = M_PI / 180.0;

// reading context: the source name for "FILE:LINE: field: message"
struct Reader {
  std::string source;

  [[noreturn]] void fail(const YAML::Node& node, const std::string& field, const std::string& msg) const {
    const int line = node.IsDefined() && !node.IsNull() ? node.Mark().line + 1 : (node.IsDefined() ? node.Mark().line + 1 : 0);
    throw ConfigError(source + ":" + std::to_string(std::max(line, 0)) + ": " + field + ": " + msg);
  }
  std::string where(const YAML::Node& node) const { return source + ":" + std::to_string(node.Mark().line + 1); }

  void onlyKeys(const YAML::Node& map, const std::string& field, std::initializer_list<const char*> keys) const {
    if (!map.IsMap()) fail(map, field, "expected a mapping");
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      bool ok = false;
      std::string list;
      for (const char* key : keys) {
        ok = ok || k == key;
        list += (list.empty() ? "" : ", ") + std::string(key);
      }
      if (!ok) fail(kv.first, field, "unknown key '" + k + "' (expected one of: " + list + ")");
    }
  }

  double number(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail(n, field, "expected a number");
    double v = 0;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(n, field, "expected a number, got '" + n.Scalar() + "'");
    }
    if (!std::isfinite(v)) fail(n, field, "must be finite");
    return v;
  }
  double nonNegative(const YAML::Node& n, const std::string& field) const {
    const double v = number(n, field);
    if (v < 0) fail(n, field, "must be >= 0, got " + n.Scalar());
    return v;
  }
  double positive(const YAML::Node& n, const std::string& field) const {
    const double v = number(n, field);
    if (v <= 0) fail(n, field, "must be > 0, got " + n.Scalar());
    return v;
  }
  bool boolean(const YAML::Node& n, const std::string& field) const {
    try {
      return n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(n, field, "expected true or false");
    }
  }
  std::string string(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail(n, field, "expected a string");
    return n.Scalar();
  }
  VectorX vector(const YAML::Node& n, const std::string& field, int size) const {
    if (!n.IsSequence() || (size >= 0 && static_cast<int>(n.size()) != size))
      fail(n, field, "expected a list of " + (size >= 0 ? std::to_string(size) + " " : std::string()) + "numbers");
    VectorX v(n.size());
    for (size_t i = 0; i < n.size(); ++i) v(i) = number(n[i], field + "[" + std::to_string(i) + "]");
    return v;
  }
  Vector6 gains(const YAML::Node& n, const std::string& field) const {
    // 6 numbers (rot xyz, lin xyz) or {rotation: r, translation: t} shorthand
    Vector6 g;
    if (n.IsMap()) {
      onlyKeys(n, field, {"rotation", "translation"});
      const double r = n["rotation"] ? nonNegative(n["rotation"], field + ".rotation") : 0.0;
      const double t = n["translation"] ? nonNegative(n["translation"], field + ".translation") : 0.0;
      g << r, r, r, t, t, t;
      return g;
    }
    g = vector(n, field, 6);
    for (int i = 0; i < 6; ++i)
      if (g(i) < 0) fail(n[i], field + "[" + std::to_string(i) + "]", "must be >= 0");
    return g;
  }
  SE3 pose(const YAML::Node& n, const std::string& field) const {
    onlyKeys(n, field, {"xyz", "rpy_deg"});
    SE3 H;
    if (n["xyz"]) H.p = vector(n["xyz"], field + ".xyz", 3);
    if (n["rpy_deg"]) {
      const VectorX rpy = vector(n["rpy_deg"], field + ".rpy_deg", 3) * kDeg;
      // R = Rz(yaw) Ry(pitch) Rx(roll)
      H.R = (Eigen::AngleAxisd(rpy(2), Vector3::UnitZ()) * Eigen::AngleAxisd(rpy(1), Vector3::UnitY()) *
             Eigen::AngleAxisd(rpy(0), Vector3::UnitX()))
                .toRotationMatrix();
    }
    return H;
  }
  std::map<std::string, double> coordinateMap(const YAML::Node& n, const std::string& field, bool positive_only) const {
    if (!n.IsMap()) fail(n, field, "expected a mapping coordinate -> value");
    std::map<std::string, double> out;
    for (const auto& kv : n) {
      const std::string k = kv.first.as<std::string>();
      out[k] = positive_only ? positive(kv.second, field + "." + k) : nonNegative(kv.second, field + "." + k);
    }
    return out;
  }

  MechanismConfig mechanism(const YAML::Node& n, const std::string& field) const {
    onlyKeys(n, field,
             {"type", "origin", "points", "spline", "friction", "limits", "force", "normal_force", "stiffness",
              "damping", "enabled"});
    MechanismConfig m;
    if (!n["type"]) fail(n, field, "missing key 'type' (prismatic, sliding_pivot, plane, curve)");
    try {
      m.spec.type = mechanismTypeFromString(string(n["type"], field + ".type"));
    } catch (const std::invalid_argument& e) {
      fail(n["type"], field + ".type", e.what());
    }
    const int d = mechanismDimension(m.spec.type);
    if (n["origin"]) m.spec.base = pose(n["origin"], field + ".origin");
    if (n["points"]) {
      const YAML::Node& P = n["points"];
      if (!P.IsSequence()) fail(P, field + ".points", "expected a list of [x, y, z]");
      for (size_t i = 0; i < P.size(); ++i)
        m.spec.points.push_back(vector(P[i], field + ".points[" + std::to_string(i) + "]", 3));
    }
    if (n["spline"]) m.spec.spline = boolean(n["spline"], field + ".spline");
    if (n["friction"]) m.spec.friction = positive(n["friction"], field + ".friction");
    if (n["limits"]) {
      const YAML::Node& L = n["limits"];
      if (!L.IsSequence() || static_cast<int>(L.size()) != d)
        fail(L, field + ".limits", "expected " + std::to_string(d) + " pairs [lower, upper] for a " + toString(m.spec.type));
      m.spec.lower.resize(d);
      m.spec.upper.resize(d);
      for (int i = 0; i < d; ++i) {
        const std::string f = field + ".limits[" + std::to_string(i) + "]";
        if (!L[i].IsSequence() || L[i].size() != 2) fail(L[i], f, "expected [lower, upper]");
        // ".inf" / "-.inf" allowed for a free side
        const auto bound = [&](const YAML::Node& b) {
          double v = 0;
          try {
            v = b.as<double>();
          } catch (const YAML::Exception&) {
            fail(b, f, "expected a number");
          }
          if (std::isnan(v)) fail(b, f, "must not be NaN");
          return v;
        };
        m.spec.lower(i) = bound(L[i][0]);
        m.spec.upper(i) = bound(L[i][1]);
        if (m.spec.lower(i) > m.spec.upper(i)) fail(L[i], f, "lower > upper");
      }
    }
    if (n["force"]) m.spec.force = vector(n["force"], field + ".force", d);
    if (n["normal_force"]) {
      if (m.spec.type != MechanismType::kPlane) fail(n["normal_force"], field + ".normal_force", "only for a plane");
      if (m.spec.force.size() == 0) m.spec.force = VectorX::Zero(d);
      m.spec.force(3) = -number(n["normal_force"], field + ".normal_force");
    }
    if (n["stiffness"]) m.stiffness = gains(n["stiffness"], field + ".stiffness");
    if (n["damping"]) m.damping = gains(n["damping"], field + ".damping");
    if (n["enabled"]) m.enabled = boolean(n["enabled"], field + ".enabled");
    try {
      VirtualMechanism check(m.spec);
    } catch (const std::invalid_argument& e) {
      fail(n, field, e.what());
    }
    return m;
  }
};

YAML::Node parseYaml(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ":0: cannot open controller config");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

ControllerConfig parseControllerConfig(const std::string& yaml_text, const std::string& source) {
  const Reader r{source};
  const YAML::Node root = parseYaml(yaml_text, source);
  if (!root.IsMap()) throw ConfigError(source + ":1: expected a mapping (dt_s, gravity, b_a, internal, control_frames, ...)");
  r.onlyKeys(root, "config",
             {"dt_s", "gravity", "b_a", "internal", "projector", "coupling_error", "rank_tolerance", "control_frames"});
  ControllerConfig c;
  c.source = source;
  if (root["dt_s"]) {
    c.dt = r.positive(root["dt_s"], "dt_s");
    if (c.dt > 0.1) r.fail(root["dt_s"], "dt_s", "must be <= 0.1 s (first-order Euler, 2.11)");
  }
  if (root["gravity"]) c.gravity = r.vector(root["gravity"], "gravity", 3);
  if (const YAML::Node n = root["b_a"]) {
    r.onlyKeys(n, "b_a", {"root_linear", "root_angular", "joints", "coordinates"});
    if (n["root_linear"]) c.b_a.root_linear = r.positive(n["root_linear"], "b_a.root_linear");
    if (n["root_angular"]) c.b_a.root_angular = r.positive(n["root_angular"], "b_a.root_angular");
    if (n["joints"]) c.b_a.joints = r.positive(n["joints"], "b_a.joints");
    if (n["coordinates"]) c.b_a.coordinates = r.coordinateMap(n["coordinates"], "b_a.coordinates", true);
  }
  if (const YAML::Node n = root["internal"]) {
    r.onlyKeys(n, "internal", {"enabled", "stiffness", "damping", "coordinates", "posture", "projection", "energy_observer"});
    if (n["enabled"]) c.internal.enabled = r.boolean(n["enabled"], "internal.enabled");
    if (n["stiffness"]) c.internal.stiffness = r.nonNegative(n["stiffness"], "internal.stiffness");
    if (n["damping"]) c.internal.damping = r.nonNegative(n["damping"], "internal.damping");
    if (n["coordinates"]) c.internal.coordinates = r.coordinateMap(n["coordinates"], "internal.coordinates", false);
    if (n["posture"]) {
      c.internal.posture = r.string(n["posture"], "internal.posture");
      if (c.internal.posture != "standing" && c.internal.posture != "neutral")
        r.fail(n["posture"], "internal.posture", "expected 'standing' or 'neutral', got '" + c.internal.posture + "'");
    }
    if (n["projection"]) {
      const std::string p = r.string(n["projection"], "internal.projection");
      if (p == "dynamic") c.internal.projection = InternalProjection::kDynamic;
      else if (p == "none") c.internal.projection = InternalProjection::kNone;
      else r.fail(n["projection"], "internal.projection", "expected 'dynamic' or 'none', got '" + p + "'");
    }
    if (const YAML::Node o = n["energy_observer"]) {
      const std::string f = "internal.energy_observer";
      r.onlyKeys(o, f, {"enabled", "budget_J", "decay_per_s", "recovery_per_s", "alpha_min"});
      auto& ob = c.internal.observer;
      if (o["enabled"]) ob.enabled = r.boolean(o["enabled"], f + ".enabled");
      if (o["budget_J"]) ob.budget = r.positive(o["budget_J"], f + ".budget_J");
      if (o["decay_per_s"]) ob.decay_per_s = r.nonNegative(o["decay_per_s"], f + ".decay_per_s");
      if (o["recovery_per_s"]) ob.recovery_per_s = r.nonNegative(o["recovery_per_s"], f + ".recovery_per_s");
      if (o["alpha_min"]) {
        ob.alpha_min = r.nonNegative(o["alpha_min"], f + ".alpha_min");
        if (ob.alpha_min > 1) r.fail(o["alpha_min"], f + ".alpha_min", "must be in [0, 1]");
      }
    }
  }
  if (root["projector"]) {
    const std::string p = r.string(root["projector"], "projector");
    if (p == "ldlt") c.projector = ProjectorMethod::kLdlt;
    else if (p == "svd") c.projector = ProjectorMethod::kSvd;
    else r.fail(root["projector"], "projector", "expected 'ldlt' or 'svd', got '" + p + "'");
  }
  if (root["coupling_error"]) {
    const std::string p = r.string(root["coupling_error"], "coupling_error");
    if (p == "r3_so3") c.coupling_error = CouplingError::kR3SO3;
    else if (p == "se3") c.coupling_error = CouplingError::kSE3;
    else r.fail(root["coupling_error"], "coupling_error", "expected 'r3_so3' or 'se3', got '" + p + "'");
  }
  if (root["rank_tolerance"]) {
    c.rank_tolerance = r.positive(root["rank_tolerance"], "rank_tolerance");
    if (c.rank_tolerance >= 1) r.fail(root["rank_tolerance"], "rank_tolerance", "must be in (0, 1)");
  }
  if (const YAML::Node list = root["control_frames"]) {
    if (!list.IsSequence()) r.fail(list, "control_frames", "expected a list of control frames");
    std::set<std::string> names;
    for (size_t i = 0; i < list.size(); ++i) {
      const YAML::Node n = list[i];
      const std::string f = "control_frames[" + std::to_string(i) + "]";
      r.onlyKeys(n, f, {"name", "frame", "offset", "stiffness", "damping", "priority", "weight", "enabled", "mechanism"});
      ControlFrameConfig cf;
      cf.where = r.where(n);
      if (!n["name"]) r.fail(n, f, "missing key 'name'");
      cf.name = r.string(n["name"], f + ".name");
      if (!names.insert(cf.name).second) r.fail(n["name"], f + ".name", "duplicate control frame '" + cf.name + "'");
      cf.frame = n["frame"] ? r.string(n["frame"], f + ".frame") : cf.name;
      if (n["offset"]) cf.offset = r.pose(n["offset"], f + ".offset");
      if (!n["stiffness"]) r.fail(n, f, "missing key 'stiffness' (6 numbers: rot xyz N·m/rad, lin xyz N/m)");
      cf.stiffness = r.gains(n["stiffness"], f + ".stiffness");
      if (n["damping"]) cf.damping = r.gains(n["damping"], f + ".damping");
      if (n["priority"]) {
        const double p = r.nonNegative(n["priority"], f + ".priority");
        if (p != std::floor(p) || p > 100) r.fail(n["priority"], f + ".priority", "expected an integer level in [0, 100]");
        cf.priority = static_cast<int>(p);
      }
      if (n["weight"]) cf.weight = r.positive(n["weight"], f + ".weight");
      if (n["enabled"]) cf.enabled = r.boolean(n["enabled"], f + ".enabled");
      if (n["mechanism"]) cf.mechanism = r.mechanism(n["mechanism"], f + ".mechanism");
      c.frames.push_back(std::move(cf));
    }
  }
  return c;
}

ControllerConfig loadControllerConfig(const std::string& path) { return parseControllerConfig(readFile(path), path); }

MechanismConfig parseMechanismConfig(const std::string& yaml_text, const std::string& source) {
  const Reader r{source};
  const YAML::Node root = parseYaml(yaml_text, source);
  return r.mechanism(root, "mechanism");
}

}  // namespace mannequin::control
