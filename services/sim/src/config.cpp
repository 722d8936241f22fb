#include "mannequin/simservice/config.hpp"

#include "mannequin/skeleton/anthropometry.hpp"

namespace mannequin::simservice {

using core::ConfigNode;

SimServiceConfig parseSimConfig(const ConfigNode& root) {
  root.allowOnly({"name", "publish", "connect", "mode", "step", "world_rate", "publish_on_mocap", "interpolation_delay",
                  "reanchor_threshold", "occlusion", "calibration", "gains", "collision", "mannequins", "stepper",
                  "target_twist", "joint_limits"});
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
  for (const ConfigNode& m : root["mannequins"].items()) {
    m.allowOnly({"name", "config", "root_frame", "control_frames", "controller"});
    MannequinEntry e;
    e.where = m.where();
    e.field = m.path();
    e.name = m["name"].str();
    e.config = m["config"].str();
    e.root_frame = m.get("root_frame", e.root_frame);
    e.controller = m.get("controller", e.controller);
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

}  // namespace mannequin::simservice
