#include "mannequin/sim/world.hpp"

#include "mannequin/balance/static_balance.hpp"
#include "mannequin/balance/variational_balance.hpp"
#include "mannequin/scenario/engine.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <cmath>
#include <set>
#include <stdexcept>

#include "mannequin/constraints/swing_twist.hpp"
#include "mannequin/control/first_order.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/sim/controller_stepper.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

namespace mannequin::sim {

namespace {
/// max over limited coordinates of how far q is past a limit (rad, ≥ 0): revolute coordinates against
/// their bounds, ball joints against their swing ellipse and twist range (Annex D.2, swing_twist.hpp).
double worstLimitExcess(const skeleton::Model& model, const skeleton::VectorX& q) {
  double worst = 0.0;
  for (const skeleton::Joint& j : model.joints) {
    if (j.type == skeleton::JointType::kFreeFlyer) continue;
    if (j.type == skeleton::JointType::kBall) {
      // the rotation angle θ = |q| bounds the swing angle and |twist| (swing_twist.hpp), and every point of
      // the swing ellipse is at least min(a, b) − |c| from s = 0: inside both, nothing to decompose
      const skeleton::BallLimit& l = j.ball_limit;
      const double theta = q.segment<3>(j.idx_q).norm();
      if (theta < std::min(l.swing_a, l.swing_b) - std::hypot(l.swing_cx, l.swing_cy) && theta < -l.twist_lower &&
          theta < l.twist_upper)
        continue;
      const constraints::BallLimitDistances bd = constraints::ballLimitDistances(l, math::expSO3(q.segment<3>(j.idx_q)), false);
      worst = std::max(worst, bd.swing_excess);
      if (!bd.singular) worst = std::max({worst, -bd.twist_lower, -bd.twist_upper});
      continue;
    }
    for (int c = 0; c < j.nq; ++c) {
      const int k = j.idx_q + c;
      const double lo = model.lower_limit(k), hi = model.upper_limit(k);
      if (std::isfinite(lo)) worst = std::max(worst, lo - q(k));
      if (std::isfinite(hi)) worst = std::max(worst, q(k) - hi);
    }
  }
  return worst;
}
}  // namespace

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
}  // namespace

struct World::Physics {
  collision::CollisionWorld cw;
  std::vector<int> cw_mannequin;                       // per mannequin: index in cw
  std::vector<std::unique_ptr<constraints::MannequinSystem>> systems;
  std::vector<std::unique_ptr<constraints::MannequinFrames>> frames;
  std::unique_ptr<constraints::ContactRows> contacts;
  std::vector<std::unique_ptr<constraints::JointLimitRows>> limits;  // per mannequin (joint_limits on)
  std::vector<std::unique_ptr<constraints::BalanceRows>> balance;    // per mannequin (distance; rows if balance_rows)
  std::vector<std::vector<math::Vector3>> support;     // per mannequin: foot–floor points (capacity preallocated)
  std::vector<RigidObject> objects;                    // systems nm + i
  std::vector<int> object_body;                        // per object: collision body id
  std::unique_ptr<HingeLimitRows> hinges;
  std::unique_ptr<GraspRows> grasps;
  std::unique_ptr<GuideRows> guides;
  struct GraspRecord {
    int object = -1, mannequin = -1;                   // −1: free slot
    int joint = -1;                                    // joint carrying the grasping frame
  };
  std::vector<GraspRecord> grasp_records;              // per GraspRows handle
  std::unique_ptr<constraints::ConstraintSolver> solver;
  collision::ContactSet set;
  int floor_body = -1;                                 // "scene/floor", −1 if none
  std::vector<int> body_mannequin;                     // per body: mannequin index or −1
  std::vector<int> body_object;                        // per body: object index or −1
  std::vector<char> body_is_foot;                      // per body: a foot segment ("foot*", "toes*")
  std::vector<char> stepping;                          // per mannequin: stage 1 succeeded this step
  balance::StaticBalanceSolver margin_solver;          // the force margins (one solver, reused)
  balance::StaticBalanceProblem margin_problem;
  std::vector<int> body_joint;                         // per body: the joint carrying a segment, −1 if not a segment
  /// The balance controller of one mannequin (PhysicsConfig::balance_controller).
  struct BalanceLoop {
    std::unique_ptr<balance::VariationalBalanceSolver> solver;
    balance::VariationalBalanceProblem problem;
    std::vector<int> frames;       // driven frames (indices in Mannequin::frames) it takes over
    std::vector<char> taken;       // per driven frame: in `frames`
    skeleton::Data data;           // kinematics at q_b
    skeleton::VectorX q_b;         // the controller's own configuration: Algorithm 5 iterates on it
    bool driving = false;          // q_b exists and drives the frames and the posture
    double fraction = 0.0;         // of the margins asked for, the last solve held
    skeleton::VectorX k, b;        // joint coupling gains (nv; the root's 0)
    explicit BalanceLoop(const skeleton::Model& model) : data(model) {}
  };
  std::vector<BalanceLoop> balance_loops;              // per mannequin when the controller is on
  explicit Physics(const collision::WorldOptions& o) : cw(o) {}
  /// Whether mannequin m holds object o (contacts between them are ignored).
  bool holds(int m, int o) const {
    for (const GraspRecord& g : grasp_records)
      if (g.mannequin == m && g.object == o) return true;
    return false;
  }
};

/// A mocap source: its frames, and the anchor of its capture clock to the World clock.
struct World::Source {
  std::string name;
  MocapBuffer buffer{2.0};
  bool anchored = false;
  bool gap = false;   // its newest frame is older than occlusion_hold (counted once per gap)
  bool back = false;  // frames came back after a gap or the clock was re-anchored: the next step starts the catch-up
  std::int64_t anchor_capture_ns = 0;
  std::uint64_t anchor_step = 0;
};

struct World::Mannequin {
  std::string name;
  skeleton::Model model;
  std::vector<ControlFrameSpec> specs;
  int root_frame = -1;
  int source = 0;  // index in World::sources_
  std::vector<int> frame_indices;
  std::unique_ptr<Stepper> stepper;
  std::vector<DrivenFrame> frames;
  std::vector<math::SE3> previous_targets;  // targets of the previous step (target twist)
  std::vector<bool> have_previous;
  std::vector<double> weights;  // current weights (rate-limited)
  // after a stream gap: the offset (world, m and rotation vector) of each target from its body, shrinking at kCatchUpSpeed
  std::vector<math::Vector3> catch_p, catch_r;
  bool calibrated = false;
  skeleton::VectorX q_standing;
  skeleton::VectorX q_posture;  // q_c: the posture target set at calibration
  bool holding_restored = false;  // restored calibrated, its source not anchored yet: holds the restored targets
};

World::World(std::vector<MannequinSetup> setups, const SimConfig& config) : config_(config) {
  if (!(config_.step > 0) || !std::isfinite(config_.step)) throw std::invalid_argument("sim: step must be > 0");
  sources_.push_back(std::make_unique<Source>());  // the default source ""
  std::set<std::string> names;
  for (MannequinSetup& s : setups) {
    if (!names.insert(s.name).second) throw std::invalid_argument("sim: two mannequins named '" + s.name + "'");
    auto m = std::make_unique<Mannequin>();
    if (findSource(s.mocap_source) == nullptr) {
      sources_.push_back(std::make_unique<Source>());
      sources_.back()->name = s.mocap_source;
    }
    for (std::size_t i = 0; i < sources_.size(); ++i)
      if (sources_[i]->name == s.mocap_source) m->source = static_cast<int>(i);
    m->name = s.name;
    m->model = std::move(s.model);
    m->specs = s.frames;
    m->root_frame = m->model.findFrame(s.root_frame);
    std::vector<int> idx;
    for (const ControlFrameSpec& f : s.frames) {
      DrivenFrame st;
      st.frame = f.frame;
      st.body = f.body;
      try {
        st.frame_index = m->model.frameIndex(f.frame);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("sim: mannequin '" + s.name + "': " + e.what());
      }
      idx.push_back(st.frame_index);
      m->frames.push_back(st);
    }
    m->weights.assign(m->frames.size(), 0.0);
    m->catch_p.assign(m->frames.size(), math::Vector3::Zero());
    m->catch_r.assign(m->frames.size(), math::Vector3::Zero());
    m->q_standing = skeleton::standingConfiguration(m->model);
    m->frame_indices = idx;
    if (s.controller && config_.physics.enabled) {
      if (!config_.physics.gravity.allFinite())
        throw std::invalid_argument("sim: physics.gravity must be finite");
      s.controller->gravity = config_.physics.gravity;
    }
    if (s.controller) {
      try {
        m->stepper = std::make_unique<ControllerStepper>(m->model, *s.controller, idx, config_.step, m->q_standing,
                                                         config_.joint_limits);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("sim: mannequin '" + s.name + "': " + e.what());
      }
    } else {
      m->stepper = std::make_unique<KinematicTracker>(m->model, idx, config_.gains, m->q_standing);
    }
    m->previous_targets.resize(idx.size());
    m->have_previous.assign(idx.size(), false);
    for (auto& st : m->frames) st.target = st.actual = m->stepper->data().oMf[st.frame_index];
    mannequins_.push_back(std::move(m));
  }
  mannequin_diagnostics_.assign(mannequins_.size(), MannequinDiagnostics{});
  if (config_.physics.enabled) buildPhysics();
}

void World::buildPhysics() {
  const PhysicsConfig& pc = config_.physics;
  if (!(pc.segment_margin >= 0) || !std::isfinite(pc.segment_margin))
    throw std::invalid_argument("sim: physics.segment_margin must be finite and >= 0");
  if (pc.query_period_steps < 1) throw std::invalid_argument("sim: physics.query_period_steps must be >= 1");
  if (!(pc.activation_distance > 0) || !std::isfinite(pc.activation_distance))
    throw std::invalid_argument("sim: physics.activation_distance must be finite and > 0");
  collision::WorldOptions wo;
  wo.activation_distance = pc.activation_distance;
  physics_ = std::make_unique<Physics>(wo);
  Physics& P = *physics_;
  collision::SceneSpec scene = pc.scene;
  scene.activation_distance = pc.activation_distance;  // the physics' candidates, not the scene file's display range
  P.cw.addScene(scene);
  std::vector<constraints::ConstrainedSystem*> systems;
  for (auto& mp : mannequins_) {
    auto* cs = dynamic_cast<ControllerStepper*>(mp->stepper.get());
    if (cs == nullptr)
      throw std::invalid_argument("sim: mannequin '" + mp->name + "': physics needs the controller stepper (stepper: controller)");
    collision::MannequinOptions mo;
    mo.name = mp->name;
    mo.margin = pc.segment_margin;
    mo.self_collision = pc.self_collision;
    mo.exclude_pairs = touchingWhenStanding(mp->model, mo, pc.activation_distance);
    P.cw_mannequin.push_back(P.cw.addMannequin(mp->model, mo));
    // not yet calibrated: no place of its own (it stands where it was built, where the others may
    // stand too), it touches only the static scene and itself
    P.cw.setMannequinPlaced(P.cw_mannequin.back(), false);
    P.systems.push_back(std::make_unique<constraints::MannequinSystem>(cs->controller()));
    P.frames.push_back(std::make_unique<constraints::MannequinFrames>(mp->model, cs->controller().data()));
    systems.push_back(P.systems.back().get());
  }
  // the scene's movable bodies with a mass: rigid objects, systems after the mannequins
  if (!(pc.object_time_constant > 0) || !std::isfinite(pc.object_time_constant))
    throw std::invalid_argument("sim: physics.object_time_constant must be finite and > 0");
  std::vector<int> object_spec;
  P.objects = makeObjects(scene, &object_spec, pc.object_time_constant);
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    const int b = P.cw.findBody("scene/" + scene.bodies[static_cast<std::size_t>(object_spec[i])].name);
    if (b < 0) throw std::logic_error("sim: object '" + P.objects[i].name() + "' has no collision body");
    P.object_body.push_back(b);
    P.cw.setBodyPose(b, P.objects[i].pose());
    systems.push_back(&P.objects[i]);
  }
  // materials: the scene's, then the segments'; μ from the scene's table (default_mu elsewhere)
  std::vector<std::string> materials{scene.default_material};
  const auto material = [&](const std::string& name) {
    for (std::size_t i = 0; i < materials.size(); ++i)
      if (materials[i] == name) return static_cast<int>(i);
    materials.push_back(name);
    return static_cast<int>(materials.size()) - 1;
  };
  const int n = P.cw.bodyCount();
  std::vector<constraints::BodyBinding> bindings(static_cast<std::size_t>(n));
  P.body_mannequin.assign(static_cast<std::size_t>(n), -1);
  P.body_object.assign(static_cast<std::size_t>(n), -1);
  P.body_is_foot.assign(static_cast<std::size_t>(n), 0);
  P.body_joint.assign(static_cast<std::size_t>(n), -1);
  for (int b = 0; b < n; ++b) {
    constraints::BodyBinding& bb = bindings[static_cast<std::size_t>(b)];
    bb.margin = P.cw.margin(b);
    bb.static_pose = P.cw.bodyPose(b);
    const std::string& bname = P.cw.bodyName(b);
    if (bname == "scene/floor") P.floor_body = b;
    for (const collision::BodySpec& bs : scene.bodies)
      if ("scene/" + bs.name == bname) bb.material = material(bs.material);
  }
  const int nm = static_cast<int>(mannequins_.size());
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    const int b = P.object_body[i];
    constraints::BodyBinding& bb = bindings[static_cast<std::size_t>(b)];
    bb.system = nm + static_cast<int>(i);
    bb.frames = &P.objects[i];
    bb.local = 0;
    P.body_object[static_cast<std::size_t>(b)] = static_cast<int>(i);
  }
  const int seg_material = material(pc.segment_material);
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    const skeleton::Model& model = mannequins_[m]->model;
    for (std::size_t sgi = 0; sgi < model.segments.size(); ++sgi) {
      const int b = P.cw.segmentBody(P.cw_mannequin[m], static_cast<int>(sgi));
      if (b < 0) continue;
      constraints::BodyBinding& bb = bindings[static_cast<std::size_t>(b)];
      bb.system = static_cast<int>(m);
      bb.frames = P.frames[m].get();
      bb.local = model.segments[sgi].joint;
      bb.material = seg_material;
      P.body_mannequin[static_cast<std::size_t>(b)] = static_cast<int>(m);
      const std::string& sn = model.segments[sgi].name;
      P.body_is_foot[static_cast<std::size_t>(b)] = sn.rfind("foot", 0) == 0 || sn.rfind("toes", 0) == 0;
      P.body_joint[static_cast<std::size_t>(b)] = model.segments[sgi].joint;
    }
  }
  constraints::ContactOptions co = pc.contacts;
  const int n_materials = static_cast<int>(materials.size());
  co.mu = Eigen::MatrixXd::Constant(n_materials, n_materials, scene.default_mu);
  for (const collision::FrictionPair& fp : scene.friction) {
    const int a = material(fp.a), b = material(fp.b);
    if (a >= co.mu.rows() || b >= co.mu.rows()) continue;  // a material no body uses
    co.mu(a, b) = co.mu(b, a) = fp.mu;
  }
  P.contacts = std::make_unique<constraints::ContactRows>(std::move(bindings), co);
  P.solver = std::make_unique<constraints::ConstraintSolver>(systems, pc.solver);
  // the joint limits (and swing/twist) in the same LCP as the contacts: each sees the other's force
  if (config_.joint_limits)
    for (std::size_t m = 0; m < mannequins_.size(); ++m) {
      auto& cs = static_cast<ControllerStepper&>(*mannequins_[m]->stepper);
      P.limits.push_back(std::make_unique<constraints::JointLimitRows>(cs.controller(), static_cast<int>(m), *config_.joint_limits));
      P.solver->addProducer(P.limits.back().get());
    }
  P.solver->addProducer(P.contacts.get());
  // hinge limits of the hinged objects, grasps of any object by any mannequin body
  std::vector<HingeLimitRows::Entry> hinged;
  std::vector<const RigidObject*> all_objects;
  std::vector<int> object_systems;
  int max_nv = 6;
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    if (P.objects[i].hinged()) hinged.push_back({&P.objects[i], nm + static_cast<int>(i)});
    all_objects.push_back(&P.objects[i]);
    object_systems.push_back(nm + static_cast<int>(i));
  }
  for (const auto& mp : mannequins_) max_nv = std::max(max_nv, mp->model.nv);
  if (!hinged.empty()) {
    P.hinges = std::make_unique<HingeLimitRows>(std::move(hinged));
    P.solver->addProducer(P.hinges.get());
  }
  if (!P.objects.empty()) {
    P.guides = std::make_unique<GuideRows>(all_objects, object_systems);
    P.solver->addProducer(P.guides.get());
    P.grasps = std::make_unique<GraspRows>(std::move(all_objects), std::move(object_systems), max_nv);
    P.solver->addProducer(P.grasps.get());
    P.grasp_records.assign(8, {});  // GraspRows' default max_grasps
  }
  // balance: the support region of each mannequin's feet, its CoM distance, and (balance_rows) its row
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    auto& cs = static_cast<ControllerStepper&>(*mannequins_[m]->stepper);
    P.balance.push_back(std::make_unique<constraints::BalanceRows>(static_cast<int>(m), mannequins_[m]->model,
                                                                   cs.controller().data(), pc.balance));
    P.support.emplace_back();
    P.support.back().reserve(static_cast<std::size_t>(pc.balance.max_points));
    if (pc.balance_rows) P.solver->addProducer(P.balance.back().get());
  }
  // the balance controller (Algorithm 5 in the loop): one solver per mannequin, the frames it takes over
  const BalanceControllerConfig& bc = pc.balance_controller;
  if (bc.enabled) {
    const std::string where = "sim: physics.balance_controller.";
    if (!(bc.period > 0) || !std::isfinite(bc.period)) throw std::invalid_argument(where + "period must be finite and > 0");
    if (bc.edges < 3) throw std::invalid_argument(where + "edges must be >= 3");
    if (!(bc.max_step > 0) || !std::isfinite(bc.max_step)) throw std::invalid_argument(where + "max_step must be finite and > 0");
    if (!(bc.max_task_step > 0) || !std::isfinite(bc.max_task_step))
      throw std::invalid_argument(where + "max_task_step must be finite and > 0");
    if (!(bc.dq_weight > 0) || !std::isfinite(bc.dq_weight)) throw std::invalid_argument(where + "dq_weight must be finite and > 0");
    if (!(bc.posture_gain >= 0 && bc.posture_gain <= 1)) throw std::invalid_argument(where + "posture_gain must be in [0, 1]");
    if (!(bc.joint_stiffness >= 0) || !std::isfinite(bc.joint_stiffness) || !(bc.joint_damping >= 0) || !std::isfinite(bc.joint_damping))
      throw std::invalid_argument(where + "joint_stiffness and joint_damping must be finite and >= 0");
    for (const math::Vector3& v : bc.force_margins)
      if (!v.allFinite()) throw std::invalid_argument(where + "force_margins must be finite");
    for (const auto& mp : mannequins_) {
      Physics::BalanceLoop L(mp->model);
      L.solver = std::make_unique<balance::VariationalBalanceSolver>(mp->model);
      L.taken.assign(mp->frames.size(), 0);
      L.k = skeleton::VectorX::Constant(mp->model.nv, bc.joint_stiffness);
      L.b = skeleton::VectorX::Constant(mp->model.nv, bc.joint_damping);
      L.k.head<6>().setZero();
      L.b.head<6>().setZero();
      for (const std::string& f : bc.frames) {
        std::size_t i = 0;
        while (i < mp->frames.size() && mp->frames[i].frame != f) ++i;
        if (i == mp->frames.size()) {
          std::string driven;
          for (const DrivenFrame& st : mp->frames) driven += (driven.empty() ? "" : ", ") + st.frame;
          throw std::invalid_argument(where + "frames: '" + f + "' is not a driven frame of mannequin '" + mp->name +
                                      "' (driven: " + driven + ")");
        }
        L.frames.push_back(static_cast<int>(i));
        L.taken[i] = 1;
      }
      P.balance_loops.push_back(std::move(L));
    }
  }
  // the floor plane of the support regions: the floor body's plane (z = 0, +z without one)
  for (const collision::BodySpec& bs : scene.bodies)
    if (bs.name == "floor")
      for (const collision::PlacedShape& ps : bs.shapes)
        if (ps.shape.type == collision::ShapeType::kPlane) {
          const math::SE3 T = bs.pose * ps.pose;
          for (auto& b : P.balance) b->setFloor(T.act(ps.shape.normal * ps.shape.offset), T.R * ps.shape.normal);
        }
  P.stepping.assign(mannequins_.size(), 0);
  P.set.contacts.reserve(static_cast<std::size_t>(pc.solver.max_rows));
  contacts_.reserve(static_cast<std::size_t>(pc.solver.max_rows));
}

const collision::CollisionWorld* World::collisionWorld() const { return physics_ ? &physics_->cw : nullptr; }
const constraints::ConstraintSolver* World::constraintSolver() const { return physics_ ? physics_->solver.get() : nullptr; }
const skeleton::VectorX* World::balanceConfiguration(int m) const {
  if (!physics_ || physics_->balance_loops.empty()) return nullptr;
  const Physics::BalanceLoop& L = physics_->balance_loops.at(static_cast<std::size_t>(m));
  return L.driving ? &L.q_b : nullptr;
}

const MannequinDiagnostics& World::mannequinDiagnostics(int m) const {
  return mannequin_diagnostics_.at(static_cast<std::size_t>(m));
}

/// A scenario in the loop: its engine, where its frames and objects are in this World.
struct World::ScenarioRun {
  std::unique_ptr<scenario::Engine> engine;
  struct Frame {
    int mannequin = -1;
    std::size_t driven = 0;  // index in the mannequin's DrivenFrames
    int joint = -1;          // the joint carrying the frame
    // per joint of the model: 1 if its segment's contacts push on this frame — the joints whose nearest
    // control-frame joint up the tree (itself included) is this frame's (a foot's toes, a hand's fingers)
    std::vector<char> force_joints;
  };
  std::vector<Frame> frames;       // per scenario frame
  std::vector<int> objects;        // per scenario object: the World's object index
  std::vector<std::vector<int>> value_kind;  // per scenario object, per declared value: 0 angle, 1..3 x, y, z
  std::vector<int> grasp_handle;   // per scenario frame: its grasp (−1: none)
  std::vector<char> guided;        // per scenario object: 1 while a guide it attached holds it
  std::vector<const control::MechanismConfig*> mechanism;  // per scenario frame: the one its controller runs (into the engine's scenario)
  std::vector<scenario::Trigger> pending;
  scenario::Observation obs;
  long unapplied = 0;
};

World::~World() = default;

void World::setScenario(scenario::Scenario sc) {
  auto run = std::make_unique<ScenarioRun>();
  const std::string where = "sim: scenario '" + sc.name + "'";
  for (const scenario::FrameRef& f : sc.frames) {
    int m = -1;
    for (int k = 0; k < numMannequins(); ++k)
      if (name(k) == f.mannequin) m = k;
    if (m < 0) throw std::invalid_argument(where + ": no mannequin '" + f.mannequin + "' in the World");
    const Mannequin& mm = *mannequins_[static_cast<std::size_t>(m)];
    std::size_t driven = mm.frames.size();
    for (std::size_t i = 0; i < mm.frames.size(); ++i)
      if (mm.frames[i].frame == f.frame) driven = i;
    if (driven == mm.frames.size())
      throw std::invalid_argument(where + ": mannequin '" + f.mannequin + "' has no control frame '" + f.frame +
                                  "' driven by mocap (the sim config's control_frames)");
    ScenarioRun::Frame fr{m, driven, mm.model.frames[static_cast<std::size_t>(mm.frames[driven].frame_index)].joint, {}};
    std::vector<char> control_joint(mm.model.joints.size(), 0);
    for (const DrivenFrame& d : mm.frames) control_joint[static_cast<std::size_t>(mm.model.frames[static_cast<std::size_t>(d.frame_index)].joint)] = 1;
    fr.force_joints.assign(mm.model.joints.size(), 0);
    for (std::size_t j = 0; j < mm.model.joints.size(); ++j) {
      int a = static_cast<int>(j);
      while (a >= 0 && !control_joint[static_cast<std::size_t>(a)]) a = mm.model.joints[static_cast<std::size_t>(a)].parent;
      fr.force_joints[j] = a == fr.joint;
    }
    run->frames.push_back(std::move(fr));
  }
  for (const scenario::ObjectDecl& o : sc.objects) {
    const int k = physics_ ? findObject(o.name) : -1;
    if (k < 0) throw std::invalid_argument(where + ": no object '" + o.name + "' in the World (movable scene bodies, physics on)");
    std::vector<int> kinds;
    for (const std::string& v : o.values) {
      if (v == "angle" && object(k).hinged()) kinds.push_back(0);
      else if (v == "x" || v == "y" || v == "z") kinds.push_back(1 + (v[0] - 'x'));
      else
        throw std::invalid_argument(where + ": object '" + o.name + "' value '" + v +
                                    "': the World reports 'angle' (of hinged objects) and 'x', 'y', 'z' (the object's "
                                    "frame origin in the world, m)");
    }
    run->objects.push_back(k);
    run->value_kind.push_back(std::move(kinds));
  }
  // guides on objects: what the World's GuideRows cannot take is refused now, not at the action
  for (const scenario::State& st : sc.states)
    for (const std::vector<scenario::Action>* list : {&st.entry, &st.exit})
      for (const scenario::Action& a : *list) {
        if (a.kind != scenario::Action::Kind::kAttachGuide || a.object < 0 || !a.mechanism) continue;
        const std::string& on = sc.objects[static_cast<std::size_t>(a.object)].name;
        std::string why;
        if (object(run->objects[static_cast<std::size_t>(a.object)]).hinged()) why = "a hinged object is guided by its hinge already";
        else GuideRows::supports(a.mechanism->spec, &why);
        if (!why.empty()) throw std::invalid_argument(where + ": " + a.where + ": attach_guide on '" + on + "': " + why);
      }
  run->guided.assign(run->objects.size(), 0);
  run->grasp_handle.assign(run->frames.size(), -1);
  run->mechanism.assign(run->frames.size(), nullptr);
  run->obs.frames.resize(run->frames.size());
  run->obs.objects.resize(run->objects.size());
  for (std::size_t k = 0; k < run->objects.size(); ++k) run->obs.objects[k].values.resize(sc.objects[k].values.size());
  run->engine = std::make_unique<scenario::Engine>(std::move(sc));
  if (scenario_) {
    // the previous scenario's effects end with it: its mechanisms off, its grasps released, modes free
    // (gains it set stay)
    ScenarioRun& S = *scenario_;
    for (std::size_t i = 0; i < S.frames.size(); ++i) {
      Mannequin& m = *mannequins_[static_cast<std::size_t>(S.frames[i].mannequin)];
      if (S.mechanism[i] != nullptr)
        if (auto* cs = dynamic_cast<ControllerStepper*>(m.stepper.get())) cs->setMechanism(static_cast<int>(S.frames[i].driven), nullptr);
      if (S.grasp_handle[i] >= 0) release(S.grasp_handle[i]);
      m.frames[S.frames[i].driven].mode = "free";
    }
    for (std::size_t k = 0; k < S.objects.size(); ++k)
      if (S.guided[k]) detachGuide(S.objects[k]);
  }
  scenario_ = std::move(run);
}

void World::trigger(const std::string& name, const std::string& value) {
  if (scenario_) scenario_->pending.push_back({name, value});
}

const scenario::Engine* World::scenarioEngine() const { return scenario_ ? scenario_->engine.get() : nullptr; }
long World::scenarioUnappliedActions() const { return scenario_ ? scenario_->unapplied : 0; }

void World::stepScenario() {
  ScenarioRun& S = *scenario_;
  for (const ScenarioRun::Frame& f : S.frames)
    if (!mannequins_[static_cast<std::size_t>(f.mannequin)]->calibrated) {
      S.pending.clear();  // not running yet: triggers are dropped, not queued for its first step
      return;
    }
  scenario::Observation& obs = S.obs;
  obs.time = time();
  for (std::size_t i = 0; i < S.frames.size(); ++i) {
    const DrivenFrame& st = mannequins_[static_cast<std::size_t>(S.frames[i].mannequin)]->frames[S.frames[i].driven];
    obs.frames[i].pose = st.actual;
    obs.frames[i].target = st.target;  // the mocap target driveTargets just set
    obs.frames[i].force.setZero();
    if (S.grasp_handle[i] >= 0) obs.frames[i].force = -graspForce(S.grasp_handle[i]);  // the object's pull on the hand
  }
  if (physics_) {
    // the contact forces of the last step on each commanded frame's segments (normal forces: the friction
    // rows' directions are not reported); a contact's force on body a is −λ n (n from a to b)
    const Physics& P = *physics_;
    for (const ContactReport& c : contacts_)
      for (std::size_t i = 0; i < S.frames.size(); ++i) {
        const ScenarioRun::Frame& f = S.frames[i];
        const auto on = [&](int body) {
          if (body < 0 || P.body_mannequin[static_cast<std::size_t>(body)] != f.mannequin) return false;
          const int j = P.body_joint[static_cast<std::size_t>(body)];
          return j >= 0 && f.force_joints[static_cast<std::size_t>(j)] != 0;
        };
        if (on(c.body_a)) obs.frames[i].force -= c.normal_force * c.normal;
        if (on(c.body_b)) obs.frames[i].force += c.normal_force * c.normal;
      }
  }
  for (std::size_t k = 0; k < S.objects.size(); ++k) {
    const RigidObject& o = object(S.objects[k]);
    obs.objects[k].pose = o.pose();
    for (std::size_t i = 0; i < obs.objects[k].values.size(); ++i) {
      const int kind = S.value_kind[k][i];
      obs.objects[k].values[i] = kind == 0 ? o.angle() : o.pose().p(kind - 1);
    }
  }
  obs.triggers.swap(S.pending);
  S.pending.clear();
  const scenario::StepResult& r = S.engine->step(obs);
  const scenario::Scenario& sc = S.engine->scenario();
  for (const scenario::ActionCommand& a : r.actions) {
    const scenario::Action& act = *a.action;
    const bool frame_ok = act.frame >= 0 && static_cast<std::size_t>(act.frame) < S.frames.size();
    if (act.kind == scenario::Action::Kind::kGrasp && frame_ok && act.object >= 0 && physics_) {
      const ScenarioRun::Frame& f = S.frames[static_cast<std::size_t>(act.frame)];
      int& held = S.grasp_handle[static_cast<std::size_t>(act.frame)];
      if (held >= 0) release(held);  // one grasp per frame: a second one replaces the first
      held =
          grasp(f.mannequin, sc.frames[static_cast<std::size_t>(act.frame)].frame, sc.objects[static_cast<std::size_t>(act.object)].name);
    } else if (act.kind == scenario::Action::Kind::kSetGains && frame_ok) {
      const ScenarioRun::Frame& f = S.frames[static_cast<std::size_t>(act.frame)];
      auto* cs = dynamic_cast<ControllerStepper*>(mannequins_[static_cast<std::size_t>(f.mannequin)]->stepper.get());
      if (cs == nullptr) {
        ++S.unapplied;  // the kinematic tracker has no gains to set
      } else {
        try {
          cs->setGains(static_cast<int>(f.driven), act.stiffness ? &*act.stiffness : nullptr, act.damping ? &*act.damping : nullptr);
        } catch (const std::invalid_argument&) {
          ++S.unapplied;  // bad gains are refused at load: not expected
        }
      }
    } else if (act.kind == scenario::Action::Kind::kAttachGuide && act.object >= 0 && act.mechanism && physics_) {
      const std::size_t k = static_cast<std::size_t>(act.object);
      try {
        attachGuide(S.objects[k], act.mechanism->spec);
        S.guided[k] = 1;
      } catch (const std::invalid_argument&) {
        ++S.unapplied;  // validated at setScenario: not expected
      }
    } else if (act.kind == scenario::Action::Kind::kDetachGuide && act.object >= 0 && physics_) {
      const std::size_t k = static_cast<std::size_t>(act.object);
      detachGuide(S.objects[k]);  // a guide already off is not an error: the state asked for it off
      S.guided[k] = 0;
    } else if (act.kind == scenario::Action::Kind::kRelease && frame_ok) {
      int& h = S.grasp_handle[static_cast<std::size_t>(act.frame)];
      if (h >= 0) release(h);
      h = -1;
    } else {
      ++S.unapplied;
    }
  }
  for (std::size_t i = 0; i < S.frames.size(); ++i) {
    const scenario::FrameCommand& c = r.frames[i];
    Mannequin& m = *mannequins_[static_cast<std::size_t>(S.frames[i].mannequin)];
    DrivenFrame& st = m.frames[S.frames[i].driven];
    st.target = c.setpoint.pose;
    st.mode = scenario::toString(c.mode);
    // the setpoint's world twist (ω, v) as the target's body twist (Rᵀω, Rᵀv), fed forward
    math::Vector6 V;
    V.head<3>() = c.setpoint.pose.R.transpose() * c.setpoint.twist.head<3>();
    V.tail<3>() = c.setpoint.pose.R.transpose() * c.setpoint.twist.tail<3>();
    const double w = c.mode == scenario::ControlMode::kFree ? m.weights[S.frames[i].driven] : 1.0;
    m.stepper->setTarget(static_cast<int>(S.frames[i].driven), st.target, V, w);
    // constrained: the controller's virtual mechanism (thesis 4.1.1) guides the frame besides the
    // projected setpoint; attached at the switch, disabled when the mode changes
    const control::MechanismConfig* mech =
        c.mode == scenario::ControlMode::kConstrained && c.spec != nullptr && c.spec->mechanism ? &*c.spec->mechanism : nullptr;
    if (mech != S.mechanism[i]) {
      auto* cs = dynamic_cast<ControllerStepper*>(m.stepper.get());
      try {
        if (cs != nullptr) cs->setMechanism(static_cast<int>(S.frames[i].driven), mech);
      } catch (const std::invalid_argument&) {
        ++S.unapplied;  // validated at load: not expected
      }
      S.mechanism[i] = mech;
    }
  }
}

World::Source* World::findSource(const std::string& name) {
  for (auto& src : sources_)
    if (src->name == name) return src.get();
  return nullptr;
}
const World::Source* World::findSource(const std::string& name) const {
  for (const auto& src : sources_)
    if (src->name == name) return src.get();
  return nullptr;
}
std::vector<std::string> World::mocapSources() const {
  std::vector<std::string> out;
  for (const auto& src : sources_) out.push_back(src->name);
  return out;
}
const mocap::Frame* World::latestMocap(const std::string& source) const {
  const Source* src = findSource(source);
  return src != nullptr ? src->buffer.newest() : nullptr;
}
bool World::anchored(const std::string& source) const {
  const Source* src = findSource(source);
  return src != nullptr && src->anchored;
}

int World::numObjects() const { return physics_ ? static_cast<int>(physics_->objects.size()) : 0; }
const RigidObject& World::object(int i) const {
  if (i < 0 || i >= numObjects()) throw std::out_of_range("sim: no object " + std::to_string(i));
  return physics_->objects[static_cast<std::size_t>(i)];
}
RigidObject& World::object(int i) {
  if (i < 0 || i >= numObjects()) throw std::out_of_range("sim: no object " + std::to_string(i));
  return physics_->objects[static_cast<std::size_t>(i)];
}
int World::findObject(const std::string& name) const {
  for (int i = 0; i < numObjects(); ++i)
    if (physics_->objects[static_cast<std::size_t>(i)].name() == name) return i;
  return -1;
}
int World::objectBody(int i) const {
  (void)object(i);
  return physics_->object_body[static_cast<std::size_t>(i)];
}

int World::grasp(int m, const std::string& frame, const std::string& object_name) {
  if (!physics_) throw std::invalid_argument("sim: grasp needs physics (physics.enabled)");
  if (m < 0 || m >= numMannequins()) throw std::invalid_argument("sim: grasp: no mannequin " + std::to_string(m));
  const skeleton::Model& model = mannequins_[static_cast<std::size_t>(m)]->model;
  const int f = model.findFrame(frame);
  if (f < 0) throw std::invalid_argument("sim: grasp: mannequin '" + name(m) + "' has no frame '" + frame + "'");
  const int o = findObject(object_name);
  if (o < 0) throw std::invalid_argument("sim: grasp: no object '" + object_name + "' (movable scene bodies with a mass)");
  Physics& P = *physics_;
  GraspRows::Hand hand;
  hand.system = m;
  hand.frames = P.frames[static_cast<std::size_t>(m)].get();
  hand.local = model.frames[static_cast<std::size_t>(f)].joint;
  const int handle = P.grasps->grasp(hand, o);
  if (handle < 0) return -1;
  if (static_cast<std::size_t>(handle) >= P.grasp_records.size()) P.grasp_records.resize(static_cast<std::size_t>(handle) + 1);
  P.grasp_records[static_cast<std::size_t>(handle)] = {o, m, hand.local};
  // no narrow phase between the held object and its holder (they overlap by design)
  P.cw.setIgnoresMannequin(P.object_body[static_cast<std::size_t>(o)], P.cw_mannequin[static_cast<std::size_t>(m)], true);
  return handle;
}

bool World::release(int handle) {
  if (!physics_ || !physics_->grasps || !physics_->grasps->release(handle)) return false;
  Physics& P = *physics_;
  const Physics::GraspRecord g = P.grasp_records[static_cast<std::size_t>(handle)];
  P.grasp_records[static_cast<std::size_t>(handle)] = {};
  if (g.object >= 0 && g.mannequin >= 0 && !P.holds(g.mannequin, g.object))
    P.cw.setIgnoresMannequin(P.object_body[static_cast<std::size_t>(g.object)], P.cw_mannequin[static_cast<std::size_t>(g.mannequin)], false);
  return true;
}

bool World::objectHeld(int i) const {
  (void)object(i);
  return physics_->grasps && physics_->grasps->held(i);
}

math::Vector3 World::graspForce(int handle) const {
  if (!physics_ || !physics_->grasps || handle < 0 || static_cast<std::size_t>(handle) >= physics_->grasp_records.size() ||
      physics_->grasp_records[static_cast<std::size_t>(handle)].object < 0)
    return math::Vector3::Zero();
  return physics_->grasps->force(handle);
}

std::vector<GraspState> World::grasps() const {
  std::vector<GraspState> out;
  if (!physics_ || !physics_->grasps) return out;
  for (std::size_t h = 0; h < physics_->grasp_records.size(); ++h) {
    const Physics::GraspRecord& g = physics_->grasp_records[h];
    if (g.object < 0) continue;
    out.push_back({static_cast<int>(h), g.mannequin, g.joint, g.object, physics_->grasps->force(static_cast<int>(h))});
  }
  return out;
}

std::array<math::Vector3, 2> World::handForces(int m) const {
  std::array<math::Vector3, 2> out{math::Vector3::Zero(), math::Vector3::Zero()};
  if (!physics_ || m < 0 || m >= numMannequins()) return out;
  const Physics& P = *physics_;
  const skeleton::Model& model = mannequins_[static_cast<std::size_t>(m)]->model;
  std::array<int, 2> hand{-1, -1};  // the joints carrying the hand segments
  for (const skeleton::Segment& s : model.segments) {
    if (s.name == "hand_l") hand[0] = s.joint;
    if (s.name == "hand_r") hand[1] = s.joint;
  }
  for (int side = 0; side < 2; ++side) {
    if (hand[static_cast<std::size_t>(side)] < 0) continue;
    math::Vector3& f = out[static_cast<std::size_t>(side)];
    for (std::size_t h = 0; h < P.grasp_records.size(); ++h) {
      const Physics::GraspRecord& g = P.grasp_records[h];
      if (g.object >= 0 && g.mannequin == m && g.joint == hand[static_cast<std::size_t>(side)])
        f -= P.grasps->force(static_cast<int>(h));
    }
    const auto isHand = [&](int body) {
      return body >= 0 && static_cast<std::size_t>(body) < P.body_mannequin.size() &&
             P.body_mannequin[static_cast<std::size_t>(body)] == m &&
             P.body_joint[static_cast<std::size_t>(body)] == hand[static_cast<std::size_t>(side)];
    };
    for (const ContactReport& c : contacts_) {  // n from a to b: a gets −λ n, b gets +λ n
      if (isHand(c.body_a)) f -= c.normal_force * c.normal;
      if (isHand(c.body_b)) f += c.normal_force * c.normal;
    }
  }
  return out;
}

void World::attachGuide(int i, const control::MechanismSpec& spec) {
  if (!physics_ || !physics_->guides) throw std::invalid_argument("sim: a guide needs physics and a scene with objects");
  physics_->guides->attach(i, spec);
}

bool World::detachGuide(int i) { return physics_ && physics_->guides && physics_->guides->detach(i); }

const GuideRows* World::guides() const { return physics_ ? physics_->guides.get() : nullptr; }

const std::string& World::name(int m) const { return mannequins_.at(m)->name; }
const skeleton::Model& World::model(int m) const { return mannequins_.at(m)->model; }
const skeleton::Data& World::data(int m) const { return mannequins_.at(m)->stepper->data(); }
const skeleton::VectorX& World::q(int m) const { return mannequins_.at(m)->stepper->q(); }
const skeleton::VectorX& World::qdot(int m) const { return mannequins_.at(m)->stepper->qdot(); }
bool World::calibrated(int m) const { return mannequins_.at(m)->calibrated; }
const Stepper& World::stepper(int m) const { return *mannequins_.at(m)->stepper; }
const std::vector<DrivenFrame>& World::controlFrames(int m) const { return mannequins_.at(m)->frames; }

void World::anchor(std::int64_t capture_ns, const std::string& source) {
  Source* src = findSource(source);
  if (src == nullptr) return;
  if (src->anchored) src->back = true;  // re-anchored: the targets jump in capture time, they catch up instead
  src->anchored = true;
  src->anchor_capture_ns = capture_ns;
  src->anchor_step = steps_;
}

std::int64_t World::captureTimeNs(const std::string& source) const {
  const Source* src = findSource(source);
  if (src == nullptr) return 0;
  const double dt_ns = config_.step * 1e9;
  return src->anchor_capture_ns +
         static_cast<std::int64_t>(std::llround(static_cast<double>(steps_ - src->anchor_step) * dt_ns)) -
         static_cast<std::int64_t>(std::llround(config_.interpolation_delay * 1e9));
}

void World::calibrate(Mannequin& m, const mocap::Frame& frame) {
  auto find = [&](const std::string& body) -> const mocap::Body* {
    for (const mocap::Body& b : frame.bodies)
      if (b.name == body) return &b;
    return nullptr;
  };
  for (const auto& st : m.frames) {
    const mocap::Body* b = find(st.body);
    if (b == nullptr || !b->tracked) return;  // not every body visible: wait
  }
  if (config_.calibration_needs_flag && !frame.calibration_pose) return;
  // calibration configuration: standing, moved horizontally (and turned about z) under the root's body
  skeleton::VectorX qc = m.q_standing;
  if (m.root_frame >= 0)
    for (const auto& st : m.frames)
      if (st.frame_index == m.root_frame) {
        const mocap::Body* b = find(st.body);
        qc(0) = b->pose.p.x();
        qc(1) = b->pose.p.y();
        // heading of the body's x axis projected on the floor
        const math::Vector3 x = b->pose.R.col(0);
        if (std::hypot(x.x(), x.y()) > 1e-3) {
          const double yaw = std::atan2(x.y(), x.x());
          const math::Matrix3 R = math::expSO3(math::Vector3(0, 0, yaw)) * math::expSO3(qc.segment<3>(3));
          qc.segment<3>(3) = math::logSO3(R);
        }
      }
  if (config_.calibration_fit_steps > 0) {
    // fit the posture to the bodies' positions first (orientations free), so that the offsets only
    // hold what differs between the tracker's and the model's frames, not a posture mismatch
    KinematicTracker fit(m.model, m.frame_indices, config_.gains, qc);
    for (int k = 0; k < config_.calibration_fit_steps; ++k) {
      for (std::size_t i = 0; i < m.frames.size(); ++i) {
        math::SE3 T = fit.data().oMf[m.frames[i].frame_index];
        T.p = find(m.frames[i].body)->pose.p;
        fit.setTarget(static_cast<int>(i), T, 1.0);
      }
      if (!fit.step(config_.step)) break;
    }
    qc = fit.q();
  }
  if (physics_) {
    // the contact–control paradox (thesis 4.4.3): a foot target calibrated below the floor would press
    // the sole into it for the whole session. Put the lowest sole's margin shell of q_c at
    // `calibration_clearance` above the floor's, so the foot targets at the calibration pose rest on
    // the floor (the sole `margins + clearance` above it), not in it.
    const double gap = soleGap(m, qc);
    if (std::isfinite(gap)) qc(2) += config_.physics.calibration_clearance - gap;
  }
  m.stepper->reset(qc);
  m.stepper->setPosture(qc);
  m.q_posture = qc;
  if (physics_ && !physics_->balance_loops.empty()) {
    std::size_t index = 0;
    while (mannequins_[index].get() != &m) ++index;
    physics_->balance_loops[index].driving = false;  // recalibrated: the mocap drives until the next solve
  }
  std::fill(m.have_previous.begin(), m.have_previous.end(), false);
  const skeleton::Data& d = m.stepper->data();
  for (auto& st : m.frames) {
    const mocap::Body* b = find(st.body);
    st.offset = b->pose.inverse() * d.oMf[st.frame_index];
    st.target = st.actual = d.oMf[st.frame_index];
  }
  std::fill(m.weights.begin(), m.weights.end(), 1.0);
  m.calibrated = true;
  if (physics_) {
    std::size_t index = 0;
    while (mannequins_[index].get() != &m) ++index;
    physics_->cw.setMannequinPlaced(physics_->cw_mannequin[index], true);
  }
}

double World::soleGap(Mannequin& m, const skeleton::VectorX& q) {
  Physics& P = *physics_;
  std::size_t index = 0;
  while (mannequins_[index].get() != &m) ++index;
  skeleton::Data d(m.model);
  skeleton::forwardKinematics(m.model, d, q);
  const double activation = P.cw.activationDistance();
  P.cw.setActivationDistance(2.0);  // the soles may be far above or below the floor here
  P.cw.updateMannequin(P.cw_mannequin[index], d);
  collision::ContactSet set;
  P.cw.query(steps_, set);
  P.cw.setActivationDistance(activation);
  double gap = std::numeric_limits<double>::infinity();
  for (const collision::Contact& c : set.contacts) {
    const bool foot_floor = (c.body_a == P.floor_body && P.body_is_foot[static_cast<std::size_t>(c.body_b)] &&
                             P.body_mannequin[static_cast<std::size_t>(c.body_b)] == static_cast<int>(index)) ||
                            (c.body_b == P.floor_body && P.body_is_foot[static_cast<std::size_t>(c.body_a)] &&
                             P.body_mannequin[static_cast<std::size_t>(c.body_a)] == static_cast<int>(index));
    if (foot_floor) gap = std::min(gap, c.distance);  // after margins: 0 = the margin shells touch
  }
  return gap;
}

namespace {
constexpr double kJumpTolerance = 0.05;  // m: noise of a tracked position over a frame
constexpr double kCatchUpSpeed = 1.0;  // m/s: a target catching up with its body after a stream gap
}  // namespace

bool World::addMocap(const mocap::Frame& in, const std::string& source) {
  Source* src = findSource(source);
  if (src == nullptr) return false;
  const mocap::Frame* newest = src->buffer.newest();
  const bool restart = newest != nullptr && newest->stamp_ns - in.stamp_ns > src->buffer.window_ns();
  if (newest != nullptr && !restart && in.stamp_ns <= newest->stamp_ns) {
    ++(in.stamp_ns == newest->stamp_ns ? glitches_.duplicate_frames : glitches_.out_of_order_frames);
    return false;
  }
  // a tracked body with a non-finite pose (a glitch of the tracker) is taken as untracked
  const mocap::Frame* frame = &in;
  mocap::Frame clean;
  for (const mocap::Body& b : in.bodies)
    if (b.tracked && !(b.pose.p.allFinite() && b.pose.R.allFinite())) {
      if (frame == &in) clean = in;
      frame = &clean;
    }
  if (frame == &clean)
    for (mocap::Body& b : clean.bodies)
      if (b.tracked && !(b.pose.p.allFinite() && b.pose.R.allFinite())) {
        b.tracked = false;
        ++glitches_.non_finite_bodies;
      }
  // a tracked body farther from its last tracked pose than max_target_speed allows since then (a marker
  // swap): untracked in this frame, so its target holds; a body that really moved is taken again once the
  // time since its last tracked pose allows the distance. When every tracked body jumps together it is the
  // actor (or the capture: a looping file) relocated, not a swap: taken as it is.
  if (newest != nullptr && !restart) {
    std::size_t checked = 0;
    jumps_.clear();
    for (std::size_t k = 0; k < frame->bodies.size(); ++k) {
      const mocap::Body& b = frame->bodies[k];
      if (!b.tracked) continue;
      const BodySample last = src->buffer.sample(b.name, newest->stamp_ns + 1);
      if (!last.ever_tracked) continue;
      ++checked;
      const double allowed = config_.max_target_speed * static_cast<double>(frame->stamp_ns - last.last_tracked_ns) * 1e-9 + kJumpTolerance;
      if ((b.pose.p - last.pose.p).norm() > allowed) jumps_.push_back(k);
    }
    if (!jumps_.empty() && jumps_.size() < checked) {
      if (frame == &in) clean = in;
      frame = &clean;
      for (std::size_t k : jumps_) clean.bodies[k].tracked = false;
      glitches_.pose_jumps += jumps_.size();
    }
  }
  if (restart) {
    ++glitches_.capture_restarts;
    src->buffer.restart(*frame);
    if (src->anchored) anchor(frame->stamp_ns, source);  // its clock: the service's anchoring, at the frame
  } else {
    src->buffer.add(*frame);
  }
  if (src->gap) src->back = true;  // the stream is back after a gap: its frames are taken in again
  src->gap = false;
  for (auto& m : mannequins_)
    if (!m->calibrated && sources_[static_cast<std::size_t>(m->source)].get() == src) calibrate(*m, *frame);
  return true;
}

math::Vector6 World::targetTwist(Mannequin& m, std::size_t i, double dt) const {
  const math::SE3& T = m.frames[i].target;
  math::Vector6 V = math::Vector6::Zero();
  if (config_.target_twist && m.have_previous[i]) {
    const math::SE3& P = m.previous_targets[i];
    V.head<3>() = math::logSO3(P.R.transpose() * T.R) / dt;
    V.tail<3>() = T.R.transpose() * (T.p - P.p) / dt;
    // a jump (re-tracked body, re-anchored clock) is not a motion to feed forward
    if (!V.allFinite() || V.tail<3>().norm() > config_.max_target_speed ||
        0.3 * V.head<3>().norm() > config_.max_target_speed)
      V.setZero();
  }
  m.previous_targets[i] = T;
  m.have_previous[i] = true;
  return V;
}

void World::driveTargets(Mannequin& m, double dt) {
  const Source& src = *sources_[static_cast<std::size_t>(m.source)];
  if (m.calibrated && src.anchored) {
    // restored (World::restore) and holding its targets until now: the first live targets catch up from the
    // held ones, as after a stream gap (the actor may have moved while the sim was down)
    const bool was_holding = m.holding_restored;
    m.holding_restored = false;
    const std::int64_t t = captureTimeNs(src.name);
    for (std::size_t i = 0; i < m.frames.size(); ++i) {
      DrivenFrame& st = m.frames[i];
      const math::SE3 held = st.target;
      const BodySample s = src.buffer.sample(st.body, t);
      double goal = 1.0;
      if (s.tracked) {
        st.target = s.pose * st.offset;
      } else {
        const double since = static_cast<double>(t - s.last_tracked_ns) * 1e-9;
        if (s.ever_tracked) st.target = s.pose * st.offset;  // hold the last tracked pose
        goal = since <= config_.occlusion_hold
                   ? 1.0
                   : std::max(0.0, 1.0 - (since - config_.occlusion_hold) / std::max(config_.occlusion_blend, 1e-9));
      }
      if (st.tracked && !s.tracked) ++glitches_.occlusions;
      st.tracked = s.tracked;
      // weights move towards their goal at 1/blend per second (back in after an occlusion: no jump)
      const double rate = dt / std::max(config_.occlusion_blend, 1e-9);
      double& w = m.weights[i];
      w = goal > w ? std::min(goal, w + rate) : goal;
      // back after a stream gap (or re-anchored) the body may be far from the target: the target keeps the offset it
      // had to the body then and the offset shrinks at kCatchUpSpeed (m/s, and kCatchUpSpeed / 0.3 m rad/s),
      // so it moves with the body and reaches it without a jump
      if (was_holding) {
        m.catch_p[i] = held.p - st.target.p;
        m.catch_r[i] = math::logSO3(held.R * st.target.R.transpose());
      } else if (src.back && m.have_previous[i]) {
        m.catch_p[i] = m.previous_targets[i].p - st.target.p;
        m.catch_r[i] = math::logSO3(m.previous_targets[i].R * st.target.R.transpose());
      }
      if (m.catch_p[i].squaredNorm() > 0 || m.catch_r[i].squaredNorm() > 0) {
        const auto shrink = [](math::Vector3& d, double by) { d = d.norm() <= by ? math::Vector3::Zero() : math::Vector3(d * (1.0 - by / d.norm())); };
        shrink(m.catch_p[i], kCatchUpSpeed * dt);
        shrink(m.catch_r[i], kCatchUpSpeed / 0.3 * dt);
        st.target.p += m.catch_p[i];
        st.target.R = math::expSO3(m.catch_r[i]) * st.target.R;
      }
      // a target moving faster than max_target_speed (m/s) jumped (a marker swap, a re-tracked body, a
      // re-anchored clock): counted (its twist is not fed forward, targetTwist)
      if (m.have_previous[i] && (st.target.p - m.previous_targets[i].p).norm() > config_.max_target_speed * dt) ++glitches_.target_jumps;
      m.stepper->setTarget(static_cast<int>(i), st.target, targetTwist(m, i, dt), w);
    }
  } else {
    // not calibrated: no target; restored (World::restore) and waiting for its source's first frame:
    // the restored targets held at their weights
    const bool hold = m.calibrated && m.holding_restored;
    for (std::size_t i = 0; i < m.frames.size(); ++i)
      m.stepper->setTarget(static_cast<int>(i), m.frames[i].target, math::Vector6::Zero(), hold ? m.weights[i] : 0.0);
  }
}

namespace {
double seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

bool World::physicsStep() {
  using Clock = std::chrono::steady_clock;
  Physics& P = *physics_;
  const double dt = config_.step;
  bool ok = true;
  const auto t0 = Clock::now();
  // stage 1: free motion of every mannequin at q_k (kinematics and Jacobians at q_k in its controller)
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    auto& cs = static_cast<ControllerStepper&>(*mannequins_[m]->stepper);
    P.stepping[m] = cs.beginStep(dt, /*own_limits=*/false) ? 1 : 0;  // the limits are rows of the shared LCP
    if (!P.stepping[m]) {
      ok = false;
      ++failed_steps_;
    }
  }
  for (RigidObject& o : P.objects) o.computeFreeMotion(config_.physics.gravity, dt);
  const auto t1 = Clock::now();
  // contacts at q_k: a query every query_period_steps; in between, the last query's witness points are
  // re-evaluated at q_k by the contact rows
  diagnostics_.failed_collision_pairs = 0;
  if (steps_ % static_cast<std::uint64_t>(config_.physics.query_period_steps) == 0) {
    for (std::size_t m = 0; m < mannequins_.size(); ++m) {
      auto& cs = static_cast<ControllerStepper&>(*mannequins_[m]->stepper);
      P.cw.updateMannequin(P.cw_mannequin[m], cs.controller().data());
    }
    P.cw.query(steps_, P.set);
    diagnostics_.failed_collision_pairs = P.set.stats.failed_pairs;
    // a held object and the mannequin holding it: the grasp rows couple them, no contact rows
    bool any_grasp = false;
    for (const Physics::GraspRecord& g : P.grasp_records) any_grasp = any_grasp || g.object >= 0;
    if (any_grasp) {
      auto& v = P.set.contacts;
      v.erase(std::remove_if(v.begin(), v.end(),
                             [&](const collision::Contact& c) {
                               const int oa = P.body_object[static_cast<std::size_t>(c.body_a)];
                               const int ob = P.body_object[static_cast<std::size_t>(c.body_b)];
                               const int ma = P.body_mannequin[static_cast<std::size_t>(c.body_a)];
                               const int mb = P.body_mannequin[static_cast<std::size_t>(c.body_b)];
                               return (oa >= 0 && mb >= 0 && P.holds(mb, oa)) || (ob >= 0 && ma >= 0 && P.holds(ma, ob));
                             }),
              v.end());
    }
    P.contacts->setContacts(P.set);
  }
  updateSupport();
  const auto t2 = Clock::now();
  // stage 2: every row in one LCP (systems that failed stage 1 get no force: their q̇ is zero)
  diagnostics_.solver = P.solver->solve(dt);
  const auto t3 = Clock::now();
  // stage 3: integration, kinematics at q_{k+1}
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    auto& cs = static_cast<ControllerStepper&>(*mannequins_[m]->stepper);
    if (P.stepping[m] && !cs.endStep()) {
      ok = false;
      ++failed_steps_;
    }
  }
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    P.objects[i].integrate(dt);
    P.cw.setBodyPose(P.object_body[i], P.objects[i].pose());
  }
  const auto t4 = Clock::now();
  diagnostics_.free_motion_s = seconds(t0, t1);
  diagnostics_.collision_s = seconds(t1, t2);
  diagnostics_.constraints_s = seconds(t2, t3);
  diagnostics_.integrate_s = seconds(t3, t4);
  // diagnostics of the step (contacts as solved at q_k)
  const auto& cts = P.contacts->contacts();
  const auto& states = P.contacts->states();
  contacts_.clear();
  diagnostics_.contacts = 0;
  diagnostics_.active_contacts = 0;
  diagnostics_.max_penetration_m = P.contacts->maxPenetration();
  for (MannequinDiagnostics& md : mannequin_diagnostics_) {
    md.contacts = 0;
    md.foot_contact = false;
    md.sole_height_m = std::numeric_limits<double>::infinity();
  }
  for (std::size_t i = 0; i < cts.size(); ++i) {
    const collision::Contact& c = cts[i];
    const auto& st = states[i];
    if (st.row < 0) continue;
    ++diagnostics_.contacts;
    if (st.normal_force > 0) ++diagnostics_.active_contacts;
    ContactReport r;
    r.body_a = c.body_a;
    r.body_b = c.body_b;
    r.point = st.point;
    r.normal = c.normal;
    r.distance = st.distance;
    r.normal_force = st.normal_force;
    r.friction_force = st.friction_force;
    contacts_.push_back(r);
    for (const int b : {c.body_a, c.body_b}) {
      const int m = P.body_mannequin[static_cast<std::size_t>(b)];
      if (m < 0) continue;
      MannequinDiagnostics& md = mannequin_diagnostics_[static_cast<std::size_t>(m)];
      ++md.contacts;
      const int other = b == c.body_a ? c.body_b : c.body_a;
      if (P.body_is_foot[static_cast<std::size_t>(b)] && other == P.floor_body) {
        // real geometry: the distance after margins plus both margins
        const double gap = st.distance + P.cw.margin(c.body_a) + P.cw.margin(c.body_b);
        md.sole_height_m = std::min(md.sole_height_m, gap);
        // touching: pressed, or its margin shell within 1 mm of the floor's
        if (st.normal_force > 0 || st.distance <= config_.physics.foot_contact_tolerance) md.foot_contact = true;
      }
    }
  }
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    MannequinDiagnostics& md = mannequin_diagnostics_[m];
    // no foot–floor pair in range: the soles are at least the activation distance (plus margins) up
    if (!std::isfinite(md.sole_height_m)) md.sole_height_m = config_.physics.activation_distance;
    auto& cs = static_cast<ControllerStepper&>(*mannequins_[m]->stepper);
    md.worst_joint_limit_excess_rad = worstLimitExcess(mannequins_[m]->model, cs.q());
    // balance at q_k (the support and CoM the step's row saw)
    const constraints::BalanceRows::State& bs = P.balance[m]->state();
    md.balance_distance_m = bs.distance.polygon_m;
    md.com = bs.com;
    md.support_points = static_cast<int>(P.support[m].size());
  }
  if (config_.physics.force_margin_period > 0) {
    const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(config_.physics.force_margin_period / dt)));
    if (steps_ % every == 0) updateForceMargins();
  }
  if (!P.balance_loops.empty()) {
    const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(config_.physics.balance_controller.period / dt)));
    if (steps_ % every == 0) updateBalanceController();
  }
  return ok;
}

void World::updateBalanceController() {
  Physics& P = *physics_;
  const PhysicsConfig& pc = config_.physics;
  const BalanceControllerConfig& bc = pc.balance_controller;
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    Mannequin& man = *mannequins_[m];
    Physics::BalanceLoop& L = P.balance_loops[m];
    MannequinDiagnostics& md = mannequin_diagnostics_[m];
    if (!man.calibrated) continue;
    const skeleton::Data& d = man.stepper->data();  // the simulated mannequin's kinematics at q_{k+1}
    // Algorithm 5 iterates on the controller's own configuration q_b (from the simulated q at the
    // start): q_b ← q_b ⊕ δq. Re-starting each solve from the simulated q instead would make the sag
    // of the couplings under gravity the next solve's starting point, and the body would sink.
    if (!L.driving) {
      L.q_b = man.stepper->q();
      skeleton::forwardKinematics(man.model, L.data, L.q_b);
      L.fraction = 0.0;
    }
    balance::VariationalBalanceProblem& bp = L.problem;
    // the touching contacts with the static scene, as in the force margins, on the joints of their segments
    bp.contacts.clear();
    for (const ContactReport& r : contacts_) {
      const int ma = P.body_mannequin[static_cast<std::size_t>(r.body_a)], mb = P.body_mannequin[static_cast<std::size_t>(r.body_b)];
      const bool on_a = ma == static_cast<int>(m), on_b = mb == static_cast<int>(m);
      if (on_a == on_b) continue;
      const int other = on_a ? r.body_b : r.body_a;
      if (P.cw.bodyKind(other) != collision::BodyKind::kStatic) continue;
      if (!(r.normal_force > 0 || r.distance <= pc.foot_contact_tolerance)) continue;
      const int joint = P.body_joint[static_cast<std::size_t>(on_a ? r.body_a : r.body_b)];
      if (joint < 0) continue;
      balance::BodyContact c;
      c.joint = joint;
      c.local_point = d.oMi[static_cast<std::size_t>(joint)].actInv(r.point);
      c.normal = on_b ? r.normal : math::Vector3(-r.normal);
      c.mu = P.contacts->friction(r.body_a, r.body_b);
      // desired force (3.69): what the contact carries now (the LCP's normal force). With 0 the criterion
      // would spread the weight evenly over the points and pull the CoM to their centroid, and a hand
      // on the wall would be asked to let go.
      c.desired_force = r.normal_force * c.normal;
      bp.contacts.push_back(c);
    }
    // each body in contact held (Alg. 5's first loop) where the simulation has it: the controller's body is
    // brought there by log(H_d H⁻¹), at most max_task_step (m) and max_step (rad) per solve, so that the
    // equality rows stay within the step's bounds (the controller follows the contacts as simulated)
    bp.held = balance::holdCurrentPoses(bp.contacts, L.data.oMi);
    for (balance::HeldBody& h : bp.held) {
      const math::SE3& sim = d.oMi[static_cast<std::size_t>(h.joint)];
      math::Vector3 dp = sim.p - h.desired.p;
      if (dp.norm() > bc.max_task_step) dp *= bc.max_task_step / dp.norm();
      math::Vector3 dr = math::logSO3(sim.R * h.desired.R.transpose());
      if (dr.norm() > bc.max_step) dr *= bc.max_step / dr.norm();
      h.desired = math::SE3(math::expSO3(dr) * h.desired.R, h.desired.p + dp);
    }
    // the other driven frames reach for their mocap targets (3.106), unless their body is held
    bp.tasks.clear();
    for (std::size_t i = 0; i < man.frames.size(); ++i) {
      if (L.taken[i] || man.weights[i] <= 0) continue;
      const int fi = man.frames[i].frame_index;
      const int joint = man.model.frames[static_cast<std::size_t>(fi)].joint;
      bool held = false;
      for (const balance::HeldBody& h : bp.held) held = held || h.joint == joint;
      if (!held) bp.tasks.push_back({fi, man.frames[i].target.p});
    }
    bp.gravity = pc.gravity;
    bp.edges = bc.edges;
    bp.max_step = bc.max_step;
    bp.max_task_step = bc.max_task_step;
    bp.dq_weight = bc.dq_weight;
    bp.com_margins.clear();
    bp.margins_at_com = true;  // each push held at the posture's own CoM (what forceMargin measures)
    // the internal control (4.1): back towards the calibrated posture where nothing else decides
    control::differenceInPlace(man.model, L.q_b, man.q_posture, bp.dq_desired);
    bp.dq_desired *= bc.posture_gain;
    md.balance_contacts = static_cast<int>(bp.contacts.size());
    if (bp.contacts.empty()) {
      // nothing holds it (a jump): no static equilibrium; the mocap and q_c take back over
      md.balance_status = balance::BalanceStatus::kInfeasible;
      md.balance_margin_fraction = 0.0;
      ++md.balance_failures;
      if (L.driving) {
        man.stepper->setPosture(man.q_posture);
        static_cast<ControllerStepper&>(*man.stepper).controller().clearJointCoupling();
      }
      L.driving = false;
      md.balance_driving = false;
      continue;
    }
    // the margins as a continuation: a posture far from holding the pushes asked for cannot get there in
    // one small step (|δq| ≤ max_step), so each solve asks for a fraction s of them — 5 % more than
    // the last solve held, else what it held, 20 % less, none — and the fraction grows to 1 as the body
    // moves (MannequinDiagnostics::balance_margin_fraction). Infeasible even with none: reported as such.
    const math::Vector3 com_b = skeleton::centerOfMass(man.model, L.data);  // the controller's CoM, at q_b
    const double last = L.fraction;
    double tries[4] = {std::min(1.0, last + 0.05), last, std::max(0.0, last - 0.2), 0.0};
    const int ntries = bc.force_margins.empty() ? 1 : 4;
    const balance::VariationalBalanceResult* result = nullptr;
    md.balance_tasks_dropped = false;
    for (int t = 0; t < ntries; ++t) {
      if (t > 0 && tries[t] >= tries[t - 1]) continue;  // the same fraction again
      bp.force_margins.clear();
      for (const math::Vector3& F : bc.force_margins) {
        // a push s F at the CoM: the wrench (moment about the world origin, force) = (x_com × sF, sF)
        const math::Vector3 sF = tries[t] * F;
        math::Vector6 w;
        w << com_b.cross(sF), sF;
        bp.force_margins.push_back(w);
      }
      result = &L.solver->solve(bp, L.q_b);
      ++md.balance_solves;
      if (result->status == balance::BalanceStatus::kDegenerate && !bp.tasks.empty()) {
        // the tasks repeat held rows (a hand whose forearm leans on the wall): the contacts come first
        bp.tasks.clear();
        md.balance_tasks_dropped = true;
        result = &L.solver->solve(bp, L.q_b);
        ++md.balance_solves;
      }
      if (result->status == balance::BalanceStatus::kSolved) {
        L.fraction = bc.force_margins.empty() ? 1.0 : tries[t];
        break;
      }
    }
    const balance::VariationalBalanceResult& res = *result;
    md.balance_status = res.status;
    md.balance_margin_fraction = res.status == balance::BalanceStatus::kSolved ? L.fraction : 0.0;
    if (res.status == balance::BalanceStatus::kSolved) {
      L.q_b = skeleton::integrate(man.model, L.q_b, res.dq);
      skeleton::forwardKinematics(man.model, L.data, L.q_b);
      md.balance_com = res.com;
      L.driving = true;
      man.stepper->setPosture(L.q_b);
      static_cast<ControllerStepper&>(*man.stepper).controller().setJointCoupling(L.q_b, L.k, L.b);
    } else {
      ++md.balance_failures;
      // no equilibrium with these contacts even without margins: q_b holds (the last posture in equilibrium)
    }
    md.balance_driving = L.driving;
  }
}

void World::applyBalanceTargets(std::size_t m) {
  // the frames the balance controller took over: their poses at q_b, held (V_d = 0)
  const Physics::BalanceLoop& L = physics_->balance_loops[m];
  if (!L.driving) return;
  Mannequin& man = *mannequins_[m];
  for (const int i : L.frames) {
    DrivenFrame& st = man.frames[static_cast<std::size_t>(i)];
    st.target = L.data.oMf[static_cast<std::size_t>(st.frame_index)];
    man.stepper->setTarget(i, st.target, math::Vector6::Zero(), man.weights[static_cast<std::size_t>(i)]);
  }
}

void World::updateForceMargins() {
  Physics& P = *physics_;
  const PhysicsConfig& pc = config_.physics;
  static const std::vector<math::Vector3> kHorizontal = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    MannequinDiagnostics& md = mannequin_diagnostics_[m];
    if (!mannequins_[m]->calibrated) {
      md.force_margin_n = std::numeric_limits<double>::quiet_NaN();
      md.force_margin_contacts = 0;
      continue;
    }
    balance::StaticBalanceProblem& bp = P.margin_problem;
    bp.contacts.clear();
    for (const ContactReport& r : contacts_) {
      const int ma = P.body_mannequin[static_cast<std::size_t>(r.body_a)], mb = P.body_mannequin[static_cast<std::size_t>(r.body_b)];
      const bool on_a = ma == static_cast<int>(m), on_b = mb == static_cast<int>(m);
      if (on_a == on_b) continue;  // not this mannequin's, or a self contact
      const int other = on_a ? r.body_b : r.body_a;
      if (P.cw.bodyKind(other) != collision::BodyKind::kStatic) continue;  // objects and mannequins move
      if (!(r.normal_force > 0 || r.distance <= pc.foot_contact_tolerance)) continue;
      // the normal points from a to b: the scene pushes the mannequin along it when the mannequin is b
      bp.contacts.push_back({r.point, on_b ? r.normal : math::Vector3(-r.normal), P.contacts->friction(r.body_a, r.body_b), math::Vector3::Zero()});
    }
    md.force_margin_contacts = static_cast<int>(bp.contacts.size());
    if (bp.contacts.empty()) {
      md.force_margin_n = 0.0;  // nothing holds it
      continue;
    }
    bp.mass = mannequins_[m]->model.totalMass();
    bp.gravity = pc.gravity;
    bp.fix_com = true;
    bp.desired_com = md.com;
    bp.alpha = 1.0;
    const balance::ForceMarginResult res = balance::forceMargin(P.margin_solver, bp, kHorizontal, md.com, pc.force_margin_max, 1.0);
    md.force_margin_n = res.status == balance::BalanceStatus::kSolved ? res.margin_n : 0.0;
  }
}

void World::updateSupport() {
  // each mannequin's support: the floor-side witness points of its feet's floor contacts within the
  // tolerance (the contact set of the last query, at the segment poses of that query)
  Physics& P = *physics_;
  for (auto& sp : P.support) sp.clear();
  if (P.floor_body >= 0)
    for (const collision::Contact& c : P.set.contacts) {
      if (c.distance > config_.physics.foot_contact_tolerance) continue;
      const bool a_floor = c.body_a == P.floor_body, b_floor = c.body_b == P.floor_body;
      if (a_floor == b_floor) continue;
      const int foot = a_floor ? c.body_b : c.body_a;
      if (!P.body_is_foot[static_cast<std::size_t>(foot)]) continue;
      const int m = P.body_mannequin[static_cast<std::size_t>(foot)];
      std::vector<math::Vector3>& sp = P.support[static_cast<std::size_t>(m)];
      if (sp.size() == sp.capacity()) continue;  // beyond max_points: the hull of the first ones
      sp.push_back(P.cw.bodyPose(foot).act(a_floor ? c.point_b : c.point_a));
    }
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    P.balance[m]->setSupport(P.support[m]);
    if (!config_.physics.balance_rows) P.balance[m]->evaluate();  // the distance without the row
  }
}

bool World::step() {
  const double dt = config_.step;
  bool ok = true;
  for (auto& src : sources_)
    if (const mocap::Frame* f = src->buffer.newest(); f != nullptr && src->anchored && !src->gap &&
                                                       captureTimeNs(src->name) - f->stamp_ns > std::llround(config_.occlusion_hold * 1e9)) {
      src->gap = true;
      ++glitches_.stream_gaps;
    }
  for (auto& mp : mannequins_) driveTargets(*mp, dt);
  for (auto& src : sources_) src->back = false;
  if (physics_ && !physics_->balance_loops.empty())
    for (std::size_t m = 0; m < mannequins_.size(); ++m) applyBalanceTargets(m);
  if (scenario_) stepScenario();
  if (physics_) {
    ok = physicsStep();
    diagnostics_.nan = !ok;
  } else {
    for (auto& mp : mannequins_)
      if (!mp->stepper->step(dt)) {
        ok = false;
        ++failed_steps_;
      }
    diagnostics_.nan = !ok;
    for (std::size_t m = 0; m < mannequins_.size(); ++m)
      mannequin_diagnostics_[m].worst_joint_limit_excess_rad = worstLimitExcess(mannequins_[m]->model, mannequins_[m]->stepper->q());
  }
  for (auto& mp : mannequins_) {
    Mannequin& m = *mp;
    const skeleton::Data& d = m.stepper->data();
    for (std::size_t i = 0; i < m.frames.size(); ++i) {
      DrivenFrame& st = m.frames[i];
      st.actual = d.oMf[st.frame_index];
      st.weight = m.weights[i];
      st.position_error = (st.target.p - st.actual.p).norm();
      st.orientation_error = math::logSO3(st.actual.R.transpose() * st.target.R).norm();
    }
  }
  ++steps_;
  return ok;
}

namespace {
bool finiteSE3(const math::SE3& T) {
  return T.p.allFinite() && T.R.allFinite() && (T.R.transpose() * T.R - math::Matrix3::Identity()).norm() < 1e-6 &&
         T.R.determinant() > 0;
}
}  // namespace

WorldCheckpoint World::checkpoint() const {
  WorldCheckpoint c;
  c.step = steps_;
  for (const auto& mp : mannequins_) {
    const Mannequin& m = *mp;
    MannequinCheckpoint mc;
    mc.name = m.name;
    mc.model = m.model.name;
    mc.q = m.stepper->q();
    mc.calibrated = m.calibrated;
    if (m.calibrated) {
      mc.q_posture = m.q_posture;
      for (std::size_t i = 0; i < m.frames.size(); ++i)
        mc.frames.push_back({m.frames[i].frame, m.frames[i].body, m.frames[i].offset, m.frames[i].target, m.weights[i]});
    }
    c.mannequins.push_back(std::move(mc));
  }
  for (int i = 0; i < numObjects(); ++i) {
    const RigidObject& o = object(i);
    c.objects.push_back({o.name(), o.hinged(), o.pose(), o.angle()});
  }
  return c;
}

std::vector<std::string> World::restore(const WorldCheckpoint& c) {
  // everything checked first: a refused checkpoint leaves the World as it was
  const auto fail = [](const std::string& what) { throw std::invalid_argument("sim: checkpoint: " + what); };
  if (c.mannequins.size() != mannequins_.size()) {
    std::string names;
    for (const MannequinCheckpoint& mc : c.mannequins) names += (names.empty() ? "" : ", ") + mc.name;
    fail("it has " + std::to_string(c.mannequins.size()) + " mannequin(s) (" + names + "), the World " +
         std::to_string(mannequins_.size()));
  }
  std::vector<const MannequinCheckpoint*> of(mannequins_.size(), nullptr);
  for (std::size_t k = 0; k < mannequins_.size(); ++k) {
    const Mannequin& m = *mannequins_[k];
    for (const MannequinCheckpoint& mc : c.mannequins)
      if (mc.name == m.name) of[k] = &mc;
    if (of[k] == nullptr) fail("no mannequin '" + m.name + "'");
    const MannequinCheckpoint& mc = *of[k];
    const std::string who = "mannequin '" + m.name + "': ";
    if (mc.model != m.model.name) fail(who + "model '" + mc.model + "', the World's is '" + m.model.name + "'");
    if (mc.q.size() != m.model.nq) fail(who + "q has " + std::to_string(mc.q.size()) + " coordinates, the model " + std::to_string(m.model.nq));
    if (!mc.q.allFinite()) fail(who + "q is not finite");
    if (!mc.calibrated) continue;
    if (mc.q_posture.size() != m.model.nq || !mc.q_posture.allFinite()) fail(who + "the posture target q_c is not " + std::to_string(m.model.nq) + " finite numbers");
    if (mc.frames.size() != m.frames.size()) fail(who + std::to_string(mc.frames.size()) + " driven frames, the World " + std::to_string(m.frames.size()));
    for (const DrivenFrame& st : m.frames) {
      const MannequinCheckpoint::Frame* f = nullptr;
      for (const MannequinCheckpoint::Frame& x : mc.frames)
        if (x.frame == st.frame) f = &x;
      if (f == nullptr) fail(who + "no driven frame '" + st.frame + "'");
      if (f->body != st.body) fail(who + "frame '" + st.frame + "' driven by body '" + f->body + "', in the World by '" + st.body + "'");
      if (!finiteSE3(f->offset) || !finiteSE3(f->target)) fail(who + "frame '" + st.frame + "': offset or target is not a finite rigid transform");
      if (!(f->weight >= 0.0 && f->weight <= 1.0)) fail(who + "frame '" + st.frame + "': weight not in [0, 1]");
    }
  }
  if (c.objects.size() != static_cast<std::size_t>(numObjects()))
    fail("it has " + std::to_string(c.objects.size()) + " object(s), the World " + std::to_string(numObjects()));
  std::vector<const ObjectCheckpoint*> obj(c.objects.size(), nullptr);
  for (int i = 0; i < numObjects(); ++i) {
    const RigidObject& o = object(i);
    for (const ObjectCheckpoint& oc : c.objects)
      if (oc.name == o.name()) obj[static_cast<std::size_t>(i)] = &oc;
    const ObjectCheckpoint* oc = obj[static_cast<std::size_t>(i)];
    if (oc == nullptr) fail("no object '" + o.name() + "'");
    if (oc->hinged != o.hinged()) fail("object '" + o.name() + "': hinged in one, free in the other");
    if (o.hinged() ? !std::isfinite(oc->angle) : !finiteSE3(oc->pose)) fail("object '" + o.name() + "': its pose is not finite");
  }
  // apply
  std::vector<std::string> notes;
  steps_ = c.step;
  for (std::size_t k = 0; k < mannequins_.size(); ++k) {
    Mannequin& m = *mannequins_[k];
    const MannequinCheckpoint& mc = *of[k];
    m.stepper->reset(mc.q);
    std::fill(m.have_previous.begin(), m.have_previous.end(), false);
    const skeleton::Data& d = m.stepper->data();
    m.calibrated = mc.calibrated;
    m.holding_restored = mc.calibrated;
    if (mc.calibrated) {
      m.q_posture = mc.q_posture;
      m.stepper->setPosture(mc.q_posture);
      for (std::size_t i = 0; i < m.frames.size(); ++i) {
        DrivenFrame& st = m.frames[i];
        for (const MannequinCheckpoint::Frame& f : mc.frames)
          if (f.frame == st.frame) {
            st.offset = f.offset;
            st.target = f.target;
            m.weights[i] = f.weight;
          }
      }
    } else {
      std::fill(m.weights.begin(), m.weights.end(), 0.0);
    }
    for (std::size_t i = 0; i < m.frames.size(); ++i) {
      m.frames[i].actual = d.oMf[m.frames[i].frame_index];
      m.frames[i].weight = m.weights[i];
      if (!mc.calibrated) m.frames[i].target = m.frames[i].actual;
    }
    if (physics_) {
      physics_->cw.setMannequinPlaced(physics_->cw_mannequin[k], mc.calibrated);
      if (!physics_->balance_loops.empty()) {
        if (physics_->balance_loops[k].driving) notes.push_back("mannequin '" + m.name + "': the balance controller starts again from q");
        physics_->balance_loops[k].driving = false;
      }
    }
  }
  for (int i = 0; i < numObjects(); ++i) {
    RigidObject& o = object(i);
    const ObjectCheckpoint& oc = *obj[static_cast<std::size_t>(i)];
    if (o.hinged()) o.setAngle(oc.angle);
    else o.setPose(oc.pose);
  }
  return notes;
}

}  // namespace mannequin::sim
