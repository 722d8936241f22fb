#include "mannequin/control/config.hpp"

#include <set>
#include <stdexcept>

namespace mannequin::control {

using core::ConfigNode;

namespace {

// 6 numbers (rotation xyz, translation xyz) or the {rotation: r, translation: t} shorthand, all >= 0
Vector6 gains(const ConfigNode& n) {
  Vector6 g;
  if (n.isMap()) {
    n.allowOnly({"rotation", "translation"});
    const auto r = n.find("rotation"), t = n.find("translation");
    const double rv = r ? r->nonNegative() : 0.0, tv = t ? t->nonNegative() : 0.0;
    g << rv, rv, rv, tv, tv, tv;
    return g;
  }
  if (!n.isSequence()) n.fail("expected 6 numbers (rotation xyz, translation xyz) or {rotation: r, translation: t}");
  const auto items = n.items();
  if (items.size() != 6) n.fail("expected a list of 6 numbers, got " + std::to_string(items.size()) + " values");
  for (int i = 0; i < 6; ++i) g(i) = items[i].nonNegative();
  return g;
}

// {xyz: [x, y, z] (m), rpy_deg: [roll, pitch, yaw]}
SE3 pose(const ConfigNode& n) {
  n.allowOnly({"xyz", "rpy_deg"});
  SE3 H;
  if (const auto p = n.find("xyz")) H.p = p->vec3();
  if (const auto r = n.find("rpy_deg")) H.R = r->rpyDeg();
  return H;
}

// coordinate name -> value (> 0 if `positive_only`, else >= 0)
std::map<std::string, double> coordinateMap(const ConfigNode& n, bool positive_only) {
  if (!n.isMap()) n.fail("expected a map coordinate -> value");
  std::map<std::string, double> out;
  for (const std::string& k : n.keys()) out[k] = positive_only ? n[k].positive() : n[k].nonNegative();
  return out;
}

MechanismConfig mechanism(const ConfigNode& n) {
  n.allowOnly({"type", "origin", "points", "spline", "friction", "limits", "force", "normal_force", "stiffness",
               "damping", "enabled"});
  MechanismConfig m;
  if (!n.has("type")) n.fail("missing key 'type' (prismatic, sliding_pivot, plane, curve)");
  const ConfigNode type = n["type"];
  try {
    m.spec.type = mechanismTypeFromString(type.str());
  } catch (const std::invalid_argument& e) {
    type.fail(e.what());
  }
  const int d = mechanismDimension(m.spec.type);
  if (const auto o = n.find("origin")) m.spec.base = pose(*o);
  if (const auto P = n.find("points"))
    for (const ConfigNode& p : P->items()) m.spec.points.push_back(p.vec3());
  m.spec.spline = n.get("spline", m.spec.spline);
  if (const auto f = n.find("friction")) m.spec.friction = f->positive();
  if (const auto L = n.find("limits")) {
    const auto pairs = L->items();
    if (static_cast<int>(pairs.size()) != d)
      L->fail("expected " + std::to_string(d) + " pairs [lower, upper] for a " + toString(m.spec.type));
    m.spec.lower.resize(d);
    m.spec.upper.resize(d);
    for (int i = 0; i < d; ++i) {
      const auto bounds = pairs[i].items();
      if (bounds.size() != 2) pairs[i].fail("expected [lower, upper]");
      // .inf / -.inf for a free side
      m.spec.lower(i) = bounds[0].numOrInfinity();
      m.spec.upper(i) = bounds[1].numOrInfinity();
      if (m.spec.lower(i) > m.spec.upper(i)) pairs[i].fail("lower > upper");
    }
  }
  if (const auto f = n.find("force")) m.spec.force = f->vector(d);
  if (const auto f = n.find("normal_force")) {
    if (m.spec.type != MechanismType::kPlane) f->fail("only for a plane");
    if (m.spec.force.size() == 0) m.spec.force = VectorX::Zero(d);
    m.spec.force(3) = -f->num();
  }
  if (const auto k = n.find("stiffness")) m.stiffness = gains(*k);
  if (const auto b = n.find("damping")) m.damping = gains(*b);
  m.enabled = n.get("enabled", m.enabled);
  try {
    VirtualMechanism check(m.spec);
  } catch (const std::invalid_argument& e) {
    n.fail(e.what());
  }
  return m;
}

ControllerConfig readControllerConfig(const ConfigNode& root) {
  root.allowOnly({"dt_s", "gravity", "b_a", "internal", "projector", "coupling_error", "rank_tolerance", "control_frames"});
  ControllerConfig c;
  c.source = root.file();
  if (const auto dt = root.find("dt_s")) {
    c.dt = dt->positive();
    if (c.dt > 0.1) dt->fail("must be <= 0.1 s (first-order Euler, 2.11)");
  }
  if (const auto g = root.find("gravity")) c.gravity = g->vector(3);
  if (const auto n = root.find("b_a")) {
    n->allowOnly({"root_linear", "root_angular", "joints", "coordinates"});
    if (const auto v = n->find("root_linear")) c.b_a.root_linear = v->positive();
    if (const auto v = n->find("root_angular")) c.b_a.root_angular = v->positive();
    if (const auto v = n->find("joints")) c.b_a.joints = v->positive();
    if (const auto v = n->find("coordinates")) c.b_a.coordinates = coordinateMap(*v, true);
  }
  if (const auto n = root.find("internal")) {
    n->allowOnly({"enabled", "stiffness", "damping", "coordinates", "posture", "projection", "energy_observer"});
    c.internal.enabled = n->get("enabled", c.internal.enabled);
    if (const auto v = n->find("stiffness")) c.internal.stiffness = v->nonNegative();
    if (const auto v = n->find("damping")) c.internal.damping = v->nonNegative();
    if (const auto v = n->find("coordinates")) c.internal.coordinates = coordinateMap(*v, false);
    if (const auto v = n->find("posture")) {
      static const char* const kPostures[] = {"standing", "neutral"};
      c.internal.posture = kPostures[v->choice({"standing", "neutral"})];
    }
    if (const auto v = n->find("projection"))
      c.internal.projection = v->choice({"dynamic", "none"}) == 0 ? InternalProjection::kDynamic : InternalProjection::kNone;
    if (const auto o = n->find("energy_observer")) {
      o->allowOnly({"enabled", "budget_J", "decay_per_s", "recovery_per_s", "alpha_min"});
      auto& ob = c.internal.observer;
      ob.enabled = o->get("enabled", ob.enabled);
      if (const auto v = o->find("budget_J")) ob.budget = v->positive();
      if (const auto v = o->find("decay_per_s")) ob.decay_per_s = v->nonNegative();
      if (const auto v = o->find("recovery_per_s")) ob.recovery_per_s = v->nonNegative();
      ob.alpha_min = o->getIn("alpha_min", ob.alpha_min, 0.0, 1.0);
    }
  }
  if (const auto v = root.find("projector"))
    c.projector = v->choice({"ldlt", "svd"}) == 0 ? ProjectorMethod::kLdlt : ProjectorMethod::kSvd;
  if (const auto v = root.find("coupling_error"))
    c.coupling_error = v->choice({"r3_so3", "se3"}) == 0 ? CouplingError::kR3SO3 : CouplingError::kSE3;
  if (const auto v = root.find("rank_tolerance")) {
    c.rank_tolerance = v->positive();
    if (c.rank_tolerance >= 1) v->fail("must be in (0, 1)");
  }
  if (const auto list = root.find("control_frames")) {
    std::set<std::string> names;
    for (const ConfigNode& n : list->items()) {
      n.allowOnly({"name", "frame", "offset", "stiffness", "damping", "priority", "weight", "enabled", "mechanism"});
      ControlFrameConfig cf;
      cf.where = n.where();
      const ConfigNode name = n["name"];
      cf.name = name.str();
      if (!names.insert(cf.name).second) name.fail("duplicate control frame '" + cf.name + "'");
      cf.frame = n.get("frame", cf.name);
      if (const auto o = n.find("offset")) cf.offset = pose(*o);
      if (!n.has("stiffness")) n.fail("missing key 'stiffness' (6 numbers: rot xyz N·m/rad, lin xyz N/m)");
      cf.stiffness = gains(n["stiffness"]);
      if (const auto b = n.find("damping")) cf.damping = gains(*b);
      if (const auto p = n.find("priority")) cf.priority = static_cast<int>(p->integerIn(0, 100));
      if (const auto w = n.find("weight")) cf.weight = w->positive();
      cf.enabled = n.get("enabled", cf.enabled);
      if (const auto m = n.find("mechanism")) cf.mechanism = mechanism(*m);
      c.frames.push_back(std::move(cf));
    }
  }
  return c;
}

}  // namespace

ControllerConfig parseControllerConfig(const std::string& yaml_text, const std::string& source) {
  return readControllerConfig(ConfigNode::parse(yaml_text, source));
}

ControllerConfig loadControllerConfig(const std::string& path) { return readControllerConfig(ConfigNode::load(path)); }

MechanismConfig parseMechanismConfig(const std::string& yaml_text, const std::string& source) {
  return mechanism(ConfigNode::parse(yaml_text, source));
}

MechanismConfig parseMechanismConfig(const ConfigNode& node) { return mechanism(node); }

}  // namespace mannequin::control
