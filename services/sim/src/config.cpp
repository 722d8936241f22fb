#include "mannequin/simservice/config.hpp"

#include <filesystem>

#include "mannequin/core/paths.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

namespace mannequin::simservice {

using core::ConfigNode;

std::string resolvePath(const ConfigNode& node) {
  const std::string path = node.str();
  namespace fs = std::filesystem;
  try {
    return core::findData(path);
  } catch (const core::ConfigError& e) {
    // then relative to the config file's directory
    std::error_code ec;
    const fs::path beside = fs::path(node.file()).parent_path() / path;
    if (!fs::path(path).is_absolute() && !node.file().empty() && fs::exists(beside, ec)) return beside.lexically_normal().string();
    node.fail(e.what());
  }
}

namespace {

/// The triggers' names must be the scenario's declared ones (a typo would never fire).
void checkTriggers(const ScenarioSettings& s, const std::vector<ConfigNode>* at) {
  for (std::size_t i = 0; i < s.triggers.size(); ++i)
    if (s.scenario.triggerIndex(s.triggers[i].name) < 0) {
      std::string list;
      for (const std::string& t : s.scenario.triggers) list += (list.empty() ? "" : ", ") + t;
      const std::string why = "trigger '" + s.triggers[i].name + "' is not declared by scenario '" + s.scenario.name + "' (" +
                              s.scenario.source + ": triggers: " + (list.empty() ? std::string("none") : list) + ")";
      if (at != nullptr) (*at)[i]["name"].fail(why);
      throw core::ConfigError(s.where + ": " + why);
    }
}

void loadScenarioFile(const ConfigNode& node, ScenarioSettings& s) {
  s.file = resolvePath(node);
  try {
    s.scenario = scenario::loadScenario(s.file);
  } catch (const std::exception& e) {
    node.fail(std::string("scenario: ") + e.what());  // the scenario file's own FILE:LINE error follows
  }
}

/// `scenario: FILE` or `scenario: {file, triggers: [{at, name, value}], state_rate}`.
void parseScenarioSettings(const ConfigNode& sc, ScenarioSettings& s) {
  s.where = sc.where();
  if (sc.isScalar()) {
    loadScenarioFile(sc, s);
    return;
  }
  sc.allowOnly({"file", "triggers", "state_rate"});
  loadScenarioFile(sc["file"], s);
  s.state_rate = sc.getIn("state_rate", s.state_rate, 0.1, 1000.0);
  std::vector<ConfigNode> nodes;
  if (auto tr = sc.find("triggers")) nodes = tr->items();
  for (const ConfigNode& t : nodes) {
    t.allowOnly({"at", "name", "value"});
    TimedTrigger x;
    x.at = t["at"].nonNegative();
    x.name = t["name"].str();
    x.value = t.get("value", std::string());
    if (!s.triggers.empty() && x.at < s.triggers.back().at) t["at"].fail("triggers must be listed in time order");
    s.triggers.push_back(x);
  }
  checkTriggers(s, &nodes);
}

}  // namespace

void parsePhysics(const ConfigNode& ph, sim::PhysicsConfig& p) {
  ph.allowOnly({"enabled", "gravity", "scene", "segment_margin", "segment_material", "self_collision", "query_period_steps", "activation_distance",
                "calibration_clearance", "friction_edges", "recovery_speed", "max_rows", "balance_rows",
                "foot_contact_tolerance", "object_time_constant", "balance_ellipse", "force_margin_period", "force_margin_max",
                "balance_controller"});
  p.enabled = ph.get("enabled", p.enabled);
  if (auto g = ph.find("gravity")) p.gravity = g->vec3();
  if (auto sc = ph.find("scene")) {
    const std::string path = resolvePath(*sc);
    try {
      p.scene = collision::loadScene(path);
    } catch (const std::exception& e) {
      sc->fail(std::string("scene: ") + e.what());  // the scene file's own FILE:LINE error follows
    }
  } else if (p.enabled) {
    ph.fail("enabled needs a 'scene' (a scene file, e.g. configs/scenes/floor.yaml)");
  }
  p.segment_margin = ph.getIn("segment_margin", p.segment_margin, 0.0, 0.1);
  p.segment_material = ph.get("segment_material", p.segment_material);
  if (p.segment_material.empty()) ph["segment_material"].fail("must not be empty");
  p.self_collision = ph.get("self_collision", p.self_collision);
  p.query_period_steps = ph.get("query_period_steps", p.query_period_steps);
  if (p.query_period_steps < 1) ph["query_period_steps"].fail("must be >= 1");
  p.activation_distance = ph.getIn("activation_distance", p.activation_distance, 0.0, 1.0);
  p.calibration_clearance = ph.getIn("calibration_clearance", p.calibration_clearance, 0.0, 0.1);
  p.contacts.friction_edges = ph.get("friction_edges", p.contacts.friction_edges);
  if (p.contacts.friction_edges < 0 || p.contacts.friction_edges > p.solver.max_edges)
    ph["friction_edges"].fail("must be in [0, " + std::to_string(p.solver.max_edges) + "]");
  p.contacts.recovery_speed = ph.getIn("recovery_speed", p.contacts.recovery_speed, 0.0, 100.0);
  p.solver.max_rows = ph.get("max_rows", p.solver.max_rows);
  if (p.solver.max_rows < 1 || p.solver.max_rows > 100000) ph["max_rows"].fail("must be in [1, 100000]");
  p.balance_rows = ph.get("balance_rows", p.balance_rows);
  if (auto be = ph.find("balance_ellipse")) p.balance.inscribed = be->choice({"enclosing", "inscribed"}) == 1;
  p.foot_contact_tolerance = ph.getIn("foot_contact_tolerance", p.foot_contact_tolerance, 0.0, 0.1);
  p.object_time_constant = ph.getIn("object_time_constant", p.object_time_constant, 1e-4, 10.0);
  p.force_margin_period = ph.getIn("force_margin_period", p.force_margin_period, 0.0, 3600.0);
  p.force_margin_max = ph.getIn("force_margin_max", p.force_margin_max, 1.0, 1e6);
  if (auto bc = ph.find("balance_controller")) {
    // the multi-contact balance controller in the loop (docs/balance.md)
    bc->allowOnly({"enabled", "period", "frames", "force_margins", "edges", "max_step", "max_task_step", "dq_weight",
                   "posture_gain", "joint_stiffness", "joint_damping"});
    sim::BalanceControllerConfig& b = p.balance_controller;
    b.enabled = bc->get("enabled", true);
    b.period = bc->getIn("period", b.period, 1e-4, 10.0);
    if (auto f = bc->find("frames")) b.frames = f->strings();
    if (auto fm = bc->find("force_margins")) {
      b.force_margins.clear();
      for (const ConfigNode& v : fm->items()) b.force_margins.push_back(v.vec3());
    }
    b.edges = bc->get("edges", b.edges);
    if (b.edges < 3 || b.edges > 32) (*bc)["edges"].fail("must be in [3, 32]");
    b.max_step = bc->getIn("max_step", b.max_step, 1e-5, 1.0);
    b.max_task_step = bc->getIn("max_task_step", b.max_task_step, 1e-5, 1.0);
    b.dq_weight = bc->getIn("dq_weight", b.dq_weight, 1e-6, 1e12);
    b.posture_gain = bc->getIn("posture_gain", b.posture_gain, 0.0, 1.0);
    b.joint_stiffness = bc->getIn("joint_stiffness", b.joint_stiffness, 0.0, 1e6);
    b.joint_damping = bc->getIn("joint_damping", b.joint_damping, 0.0, 1e6);
    if (b.enabled && !p.enabled) (*bc)["enabled"].fail("needs physics.enabled (the contacts come from the physics)");
  }
}

SimServiceConfig parseSimConfig(const ConfigNode& root) {
  root.allowOnly({"name", "publish", "connect", "security", "mode", "step", "world_rate", "publish_on_mocap", "interpolation_delay",
                  "reanchor_threshold", "occlusion", "calibration", "gains", "collision", "mannequins", "stepper",
                  "target_twist", "joint_limits", "physics", "mocap", "mocap_sources", "status_period", "scenario"});
  SimServiceConfig c;
  c.name = root.get("name", c.name);
  if (auto p = root.find("publish")) c.publish = p->strings();
  if (auto p = root.find("connect")) c.connect = p->strings();
  if (auto m = root.find("mode")) c.mode = m->choice({"live", "replay"}) == 0 ? Mode::kLive : Mode::kReplay;
  c.world.step = root.getIn("step", 0.001, 1e-5, 0.1);
  c.world_rate = root.getIn("world_rate", 60.0, 0.1, 1.0 / c.world.step);
  c.publish_on_mocap = root.get("publish_on_mocap", false);
  c.world.interpolation_delay = root.getIn("interpolation_delay", 0.0, 0.0, 1.0);
  if (c.mode == Mode::kReplay) c.world.interpolation_delay = 0.0;  // replay steps up to each frame: no lag needed
  c.reanchor_threshold = root.getIn("reanchor_threshold", 0.5, 0.01, 3600.0);
  if (auto o = root.find("occlusion")) {
    o->allowOnly({"hold", "blend"});
    c.world.occlusion_hold = o->getIn("hold", c.world.occlusion_hold, 0.0, 60.0);
    c.world.occlusion_blend = o->getIn("blend", c.world.occlusion_blend, 0.0, 60.0);
  }
  if (auto o = root.find("calibration")) {
    o->allowOnly({"needs_flag", "fit_steps"});
    c.world.calibration_needs_flag = o->get("needs_flag", false);
    c.world.calibration_fit_steps = o->get("fit_steps", c.world.calibration_fit_steps);
    if (c.world.calibration_fit_steps < 0) (*o)["fit_steps"].fail("must be >= 0");
  }
  if (auto st = root.find("stepper"))
    c.stepper = st->choice({"controller", "kinematic"}) == 0 ? StepperKind::kController : StepperKind::kKinematic;
  if (auto tt = root.find("target_twist")) {
    tt->allowOnly({"enabled", "max_speed"});
    c.world.target_twist = tt->get("enabled", c.world.target_twist);
    c.world.max_target_speed = tt->getIn("max_speed", c.world.max_target_speed, 0.0, 1e3);
  }
  if (auto jl = root.find("joint_limits")) {
    jl->allowOnly({"enabled", "activation", "recovery_speed"});
    if (!jl->get("enabled", true)) {
      c.world.joint_limits.reset();
    } else {
      constraints::JointLimitOptions o;
      o.activation = jl->getIn("activation", o.activation, 0.0, 1.0);
      o.recovery_speed = jl->getIn("recovery_speed", o.recovery_speed, 0.0, 100.0);
      c.world.joint_limits = o;
    }
  }
  if (auto g = root.find("gains")) {
    g->allowOnly({"task", "posture", "damping", "max_speed"});
    c.world.gains.task = g->getIn("task", c.world.gains.task, 0.0, 1e4);
    c.world.gains.posture = g->getIn("posture", c.world.gains.posture, 0.0, 1e4);
    c.world.gains.damping = g->getIn("damping", c.world.gains.damping, 1e-6, 1e3);
    c.world.gains.max_speed = g->getIn("max_speed", c.world.gains.max_speed, 1e-3, 1e4);
    if (c.world.gains.task * c.world.step >= 1.0) g->fail("task * step must be < 1 (the tracking step would overshoot)");
  }
  if (auto col = root.find("collision")) {
    col->allowOnly({"mode", "period_steps", "deadline", "replay_deadline", "margin"});
    const std::string m = col->get("mode", std::string("none"));
    if (m == "none")
      c.collision.mode = CollisionMode::kNone;
    else if (m == "service")
      c.collision.mode = CollisionMode::kService;
    else
      (*col)["mode"].fail("expected none or service (embedded comes with the constraint solver)");
    c.collision.period_steps = col->get("period_steps", c.collision.period_steps);
    if (c.collision.period_steps < 1) (*col)["period_steps"].fail("must be >= 1");
    c.collision.deadline = col->getIn("deadline", c.collision.deadline, 0.0, 10.0);
    c.collision.replay_deadline = col->getIn("replay_deadline", c.collision.replay_deadline, 0.0, 600.0);
    c.collision.margin = col->getIn("margin", c.collision.margin, 0.0, 1.0);
  }
  if (auto ph = root.find("physics")) parsePhysics(*ph, c.world.physics);
  if (auto mo = root.find("mocap")) c.mocap = resolvePath(*mo);
  c.status_period = root.getIn("status_period", c.status_period, 0.0, 3600.0);
  if (auto sc = root.find("scenario")) parseScenarioSettings(*sc, c.scenario);
  if (auto ms = root.find("mocap_sources"))
    for (const ConfigNode& s : ms->items()) {
      s.allowOnly({"name", "connect", "mocap"});
      MocapSourceEntry e;
      e.where = s.where();
      e.name = s["name"].str();
      if (e.name.empty()) s["name"].fail("must not be empty (the mocap service's name, Header.source of its frames)");
      for (const MocapSourceEntry& o : c.mocap_sources)
        if (o.name == e.name) s["name"].fail("mocap source '" + e.name + "' listed twice");
      if (auto cn = s.find("connect")) e.connect = cn->strings();
      if (auto mo = s.find("mocap")) e.mocap = resolvePath(*mo);
      c.mocap_sources.push_back(e);
    }
  for (const ConfigNode& m : root["mannequins"].items()) {
    m.allowOnly({"name", "config", "root_frame", "control_frames", "controller", "mocap_source"});
    MannequinEntry e;
    e.where = m.where();
    e.field = m.path();
    e.name = m["name"].str();
    e.config = resolvePath(m["config"]);  // from any working directory (findData, else beside the sim config)
    e.root_frame = m.get("root_frame", e.root_frame);
    if (auto ctl = m.find("controller")) {
      e.controller = resolvePath(*ctl);
    } else {
      try {
        e.controller = core::findData(e.controller);
      } catch (const core::ConfigError&) {
        // left as is: buildMannequins names it with the entry when it cannot be read
      }
    }
    if (auto src = m.find("mocap_source")) {
      e.mocap_source = src->str();
      bool known = false;
      std::string list;
      for (const MocapSourceEntry& o : c.mocap_sources) {
        known = known || o.name == e.mocap_source;
        list += (list.empty() ? "" : ", ") + o.name;
      }
      if (!known)
        src->fail("unknown mocap source '" + e.mocap_source + "' (" +
                  (list.empty() ? std::string("no mocap_sources listed") : "mocap_sources: " + list) + ")");
    }
    const ConfigNode frames = m["control_frames"];
    for (const std::string& f : frames.keys()) e.frames.push_back({f, frames[f].str()});
    if (e.frames.empty()) frames.fail("no control frame");
    c.mannequins.push_back(e);
  }
  if (c.mannequins.empty()) root["mannequins"].fail("no mannequin");
  return c;
}

SimServiceConfig loadSimConfig(const std::string& path) { return parseSimConfig(ConfigNode::load(path)); }

std::vector<sim::MannequinSetup> buildMannequins(const SimServiceConfig& config) {
  std::vector<sim::MannequinSetup> out;
  for (const MannequinEntry& e : config.mannequins) {
    // errors name the sim config's entry, then the mannequin and what failed (the file's own FILE:LINE)
    const auto fail = [&](const std::string& what) {
      if (e.where.empty()) throw core::ConfigError("mannequin '" + e.name + "': " + what);
      core::failAt(e.where, e.field, "mannequin '" + e.name + "': " + what);
    };
    sim::MannequinSetup s;
    s.name = e.name;
    try {
      s.model = skeleton::buildMannequin(skeleton::loadMannequinSpec(e.config));
    } catch (const std::exception& ex) {
      fail(std::string("config: ") + ex.what());
    }
    s.frames = e.frames;
    s.root_frame = e.root_frame;
    s.mocap_source = e.mocap_source;
    for (const auto& f : e.frames)
      if (s.model.findFrame(f.frame) < 0) {
        std::string list;
        for (const auto& fr : s.model.frames) list += (list.empty() ? "" : ", ") + fr.name;
        fail("control_frames: no frame '" + f.frame + "' in " + e.config + " (frames: " + list + ")");
      }
    if (config.stepper == StepperKind::kController) {
      try {
        s.controller = control::loadControllerConfig(e.controller);
      } catch (const std::exception& ex) {
        fail(std::string("controller: ") + ex.what());
      }
    }
    out.push_back(std::move(s));
  }
  return out;
}

void setupScenario(sim::World& world, const SimServiceConfig& config) {
  if (config.scenario.file.empty()) return;
  try {
    world.setScenario(config.scenario.scenario);
  } catch (const std::invalid_argument& e) {
    throw core::ConfigError(config.scenario.where + ": field 'scenario': " + config.scenario.file + ": " + e.what());
  }
}

void replaceScenario(SimServiceConfig& config, const std::string& file) {
  ScenarioSettings s;
  s.where = "--scenario";
  s.file = core::findData(file);
  s.scenario = scenario::loadScenario(s.file);
  s.state_rate = config.scenario.state_rate;
  if (!config.scenario.file.empty()) {
    s.triggers = config.scenario.triggers;
    s.where = config.scenario.where;
    checkTriggers(s, nullptr);
    s.where = "--scenario";
  }
  config.scenario = std::move(s);
}

int TriggerSchedule::due(sim::World& world) {
  int n = 0;
  const double now = world.time() + 0.5 * world.config().step;
  for (; next_ < triggers_->size() && (*triggers_)[next_].at <= now; ++next_, ++n)
    world.trigger((*triggers_)[next_].name, (*triggers_)[next_].value);
  return n;
}

std::size_t TriggerSchedule::skipBefore(double time) {
  std::size_t n = 0;
  for (; next_ < triggers_->size() && (*triggers_)[next_].at < time; ++next_) ++n;
  return n;
}

}  // namespace mannequin::simservice
