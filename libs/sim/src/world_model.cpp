// buildWorldModel: the checks of a World's setups and config, and its constant description.
#include "mannequin/sim/world_model.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "mannequin/collision/world.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::sim {

namespace {
/// Segment pairs of a mannequin already within the activation distance of each other (margins
/// included) in its standing configuration — thighs side by side, arms along the trunk. They are
/// excluded from its self contacts: at calibration they would start inside each other's margins and
/// the contact rows would fight the posture for the whole session (docs/constraints.md).
std::vector<std::pair<std::string, std::string>> touchingWhenStanding(const skeleton::Model& model,
                                                                      const collision::MannequinOptions& options,
                                                                      double activation) {
  collision::WorldOptions wo;
  wo.activation_distance = activation;
  collision::CollisionWorld cw(wo);
  const int mi = cw.addMannequin(model, options);
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, skeleton::standingConfiguration(model));
  cw.updateMannequin(mi, d);
  collision::ContactSet set;
  cw.query(0, set);
  std::vector<std::pair<std::string, std::string>> pairs = options.exclude_pairs;
  for (const collision::Contact& c : set.contacts) {
    std::string a = cw.bodyName(c.body_a), b = cw.bodyName(c.body_b);
    a = a.substr(a.find('/') + 1);
    b = b.substr(b.find('/') + 1);
    if (std::find(pairs.begin(), pairs.end(), std::make_pair(a, b)) == pairs.end()) pairs.emplace_back(a, b);
  }
  return pairs;
}

bool finite(double v) { return std::isfinite(v); }

void checkPhysics(const PhysicsConfig& pc) {
  if (!(pc.segment_margin >= 0) || !finite(pc.segment_margin))
    throw std::invalid_argument("sim: physics.segment_margin must be finite and >= 0");
  if (pc.query_period_steps < 1) throw std::invalid_argument("sim: physics.query_period_steps must be >= 1");
  if (!(pc.activation_distance > 0) || !finite(pc.activation_distance))
    throw std::invalid_argument("sim: physics.activation_distance must be finite and > 0");
  if (!(pc.object_time_constant > 0) || !finite(pc.object_time_constant))
    throw std::invalid_argument("sim: physics.object_time_constant must be finite and > 0");
  const BalanceControllerConfig& bc = pc.balance_controller;
  if (!bc.enabled) return;
  const std::string where = "sim: physics.balance_controller.";
  if (!(bc.period > 0) || !finite(bc.period)) throw std::invalid_argument(where + "period must be finite and > 0");
  if (bc.edges < 3) throw std::invalid_argument(where + "edges must be >= 3");
  if (!(bc.max_step > 0) || !finite(bc.max_step)) throw std::invalid_argument(where + "max_step must be finite and > 0");
  if (!(bc.max_task_step > 0) || !finite(bc.max_task_step))
    throw std::invalid_argument(where + "max_task_step must be finite and > 0");
  if (!(bc.dq_weight > 0) || !finite(bc.dq_weight)) throw std::invalid_argument(where + "dq_weight must be finite and > 0");
  if (!(bc.posture_gain >= 0 && bc.posture_gain <= 1)) throw std::invalid_argument(where + "posture_gain must be in [0, 1]");
  if (!(bc.joint_stiffness >= 0) || !finite(bc.joint_stiffness) || !(bc.joint_damping >= 0) || !finite(bc.joint_damping))
    throw std::invalid_argument(where + "joint_stiffness and joint_damping must be finite and >= 0");
  for (const math::Vector3& v : bc.force_margins)
    if (!v.allFinite()) throw std::invalid_argument(where + "force_margins must be finite");
}

/// The driven frames of `mm` the balance controller takes over, in the order of its config.
std::vector<int> balanceFrames(const MannequinModel& mm, const BalanceControllerConfig& bc) {
  std::vector<int> out;
  for (const std::string& f : bc.frames) {
    std::size_t i = 0;
    while (i < mm.control_frames.size() && mm.control_frames[i].frame != f) ++i;
    if (i == mm.control_frames.size()) {
      std::string driven;
      for (const ControlFrameSpec& c : mm.control_frames) driven += (driven.empty() ? "" : ", ") + c.frame;
      throw std::invalid_argument("sim: physics.balance_controller.frames: '" + f + "' is not a driven frame of mannequin '" +
                                  mm.name + "' (driven: " + driven + ")");
    }
    out.push_back(static_cast<int>(i));
  }
  return out;
}

PhysicsModel buildPhysicsModel(const std::vector<MannequinModel>& mannequins, const PhysicsConfig& pc) {
  PhysicsModel pm;
  pm.scene = pc.scene;
  pm.scene.activation_distance = pc.activation_distance;  // the physics' candidates, not the scene file's display range
  for (const MannequinModel& mm : mannequins) {
    collision::MannequinOptions mo;
    mo.name = mm.name;
    mo.margin = pc.segment_margin;
    mo.self_collision = pc.self_collision;
    mo.exclude_pairs = touchingWhenStanding(mm.model, mo, pc.activation_distance);
    pm.mannequin_options.push_back(std::move(mo));
  }
  const auto material = [&](const std::string& name) {
    const int i = pm.material(name);
    if (i >= 0) return i;
    pm.materials.push_back(name);
    return static_cast<int>(pm.materials.size()) - 1;
  };
  material(pm.scene.default_material);
  for (const collision::BodySpec& bs : pm.scene.bodies) material(bs.material);
  pm.segment_material = material(pc.segment_material);
  pm.contacts = pc.contacts;
  const int n = static_cast<int>(pm.materials.size());
  pm.contacts.mu = Eigen::MatrixXd::Constant(n, n, pm.scene.default_mu);
  for (const collision::FrictionPair& fp : pm.scene.friction) {
    const int a = pm.material(fp.a), b = pm.material(fp.b);
    if (a < 0 || b < 0) continue;  // a material no body uses
    pm.contacts.mu(a, b) = pm.contacts.mu(b, a) = fp.mu;
  }
  return pm;
}
}  // namespace

int PhysicsModel::material(const std::string& name) const {
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (materials[i] == name) return static_cast<int>(i);
  return -1;
}

int WorldModel::findMannequin(const std::string& name) const {
  for (std::size_t i = 0; i < mannequins.size(); ++i)
    if (mannequins[i].name == name) return static_cast<int>(i);
  return -1;
}

int WorldModel::findSource(const std::string& name) const {
  for (std::size_t i = 0; i < sources.size(); ++i)
    if (sources[i] == name) return static_cast<int>(i);
  return -1;
}

WorldModel buildWorldModel(std::vector<MannequinSetup> setups, const SimConfig& config) {
  WorldModel wm;
  wm.config = config;
  if (!(config.step > 0) || !finite(config.step)) throw std::invalid_argument("sim: step must be > 0");
  const PhysicsConfig& pc = config.physics;
  wm.sources.emplace_back();  // the default source ""
  std::set<std::string> names;
  for (MannequinSetup& s : setups) {
    if (!names.insert(s.name).second) throw std::invalid_argument("sim: two mannequins named '" + s.name + "'");
    MannequinModel mm;
    if (wm.findSource(s.mocap_source) < 0) wm.sources.push_back(s.mocap_source);
    mm.source = wm.findSource(s.mocap_source);
    mm.name = s.name;
    mm.model = std::move(s.model);
    mm.control_frames = s.frames;
    mm.root_frame = mm.model.findFrame(s.root_frame);
    for (const ControlFrameSpec& f : s.frames) {
      try {
        mm.frame_indices.push_back(mm.model.frameIndex(f.frame));
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("sim: mannequin '" + s.name + "': " + e.what());
      }
    }
    mm.q_standing = skeleton::standingConfiguration(mm.model);
    mm.controller = std::move(s.controller);
    if (mm.controller && pc.enabled) {
      if (!pc.gravity.allFinite()) throw std::invalid_argument("sim: physics.gravity must be finite");
      mm.controller->gravity = pc.gravity;
    }
    wm.mannequins.push_back(std::move(mm));
  }
  if (!pc.enabled) return wm;
  checkPhysics(pc);
  for (MannequinModel& mm : wm.mannequins) {
    if (!mm.controller)
      throw std::invalid_argument("sim: mannequin '" + mm.name + "': physics needs the controller stepper (stepper: controller)");
    if (pc.balance_controller.enabled) mm.balance_frames = balanceFrames(mm, pc.balance_controller);
  }
  wm.physics = buildPhysicsModel(wm.mannequins, pc);
  return wm;
}

}  // namespace mannequin::sim
