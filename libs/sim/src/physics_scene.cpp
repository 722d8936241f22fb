// The physics scene of a World: its runtime (PhysicsData: collision world, body bindings, row
// producers, balance loops) built from the WorldModel's PhysicsModel, and its objects, grasps and guides.
#include "world_state.hpp"

namespace mannequin::sim {

void World::buildPhysics() {
  const PhysicsConfig& pc = model_.config.physics;
  const PhysicsModel& pm = *model_.physics;
  const collision::SceneSpec& scene = pm.scene;
  std::vector<MannequinData>& mannequins = data_->mannequins;
  collision::WorldOptions wo;
  wo.activation_distance = pc.activation_distance;
  data_->physics = std::make_unique<PhysicsData>(wo);
  PhysicsData& P = *data_->physics;
  P.cw.addScene(scene);
  std::vector<constraints::ConstrainedSystem*> systems;
  for (std::size_t m = 0; m < mannequins.size(); ++m) {
    ControllerStepper* cs = mannequins[m].controller;  // set: buildWorldModel checked every mannequin has a controller
    const skeleton::Model& model = model_.mannequins[m].model;
    P.cw_mannequin.push_back(P.cw.addMannequin(model, pm.mannequin_options[m]));
    // not yet calibrated: no place of its own (it stands where it was built, where the others may
    // stand too), it touches only the static scene and itself
    P.cw.setMannequinPlaced(P.cw_mannequin.back(), false);
    P.systems.push_back(std::make_unique<MannequinSystem>(cs->controller()));
    P.frames.push_back(std::make_unique<constraints::MannequinFrames>(model, cs->controller().data()));
    systems.push_back(P.systems.back().get());
  }
  // the scene's movable bodies with a mass: rigid objects, systems after the mannequins
  std::vector<int> object_spec;
  P.objects = constraints::makeObjects(scene, &object_spec, pc.object_time_constant);
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    const int b = P.cw.findBody("scene/" + scene.bodies[static_cast<std::size_t>(object_spec[i])].name);
    if (b < 0) throw std::logic_error("sim: object '" + P.objects[i].name() + "' has no collision body");
    P.object_body.push_back(b);
    P.cw.setBodyPose(b, P.objects[i].pose());
    systems.push_back(&P.objects[i]);
  }
  // the bodies' bindings to their systems, materials (PhysicsModel::materials) and margins
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
      if ("scene/" + bs.name == bname) bb.material = pm.material(bs.material);
  }
  const int nm = static_cast<int>(mannequins.size());
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    const int b = P.object_body[i];
    constraints::BodyBinding& bb = bindings[static_cast<std::size_t>(b)];
    bb.system = nm + static_cast<int>(i);
    bb.frames = &P.objects[i];
    bb.local = 0;
    P.body_object[static_cast<std::size_t>(b)] = static_cast<int>(i);
  }
  for (std::size_t m = 0; m < mannequins.size(); ++m) {
    const skeleton::Model& model = model_.mannequins[m].model;
    for (std::size_t sgi = 0; sgi < model.segments.size(); ++sgi) {
      const int b = P.cw.segmentBody(P.cw_mannequin[m], static_cast<int>(sgi));
      if (b < 0) continue;
      constraints::BodyBinding& bb = bindings[static_cast<std::size_t>(b)];
      bb.system = static_cast<int>(m);
      bb.frames = P.frames[m].get();
      bb.local = model.segments[sgi].joint;
      bb.material = pm.segment_material;
      P.body_mannequin[static_cast<std::size_t>(b)] = static_cast<int>(m);
      const std::string& sn = model.segments[sgi].name;
      P.body_is_foot[static_cast<std::size_t>(b)] = sn.rfind("foot", 0) == 0 || sn.rfind("toes", 0) == 0;
      P.body_joint[static_cast<std::size_t>(b)] = model.segments[sgi].joint;
    }
  }
  P.contacts = std::make_unique<constraints::ContactRows>(std::move(bindings), pm.contacts);
  P.solver = std::make_unique<constraints::ConstraintSolver>(systems, pc.solver);
  // the joint limits (and swing/twist) in the same LCP as the contacts: each sees the other's force
  if (model_.config.joint_limits)
    for (std::size_t m = 0; m < mannequins.size(); ++m) {
      P.limits.push_back(std::make_unique<constraints::JointLimitRows>(*P.systems[m], static_cast<int>(m), *model_.config.joint_limits));
      P.solver->addProducer(P.limits.back().get());
    }
  P.solver->addProducer(P.contacts.get());
  // hinge limits of the hinged objects, grasps of any object by any mannequin body
  std::vector<constraints::HingeLimitRows::Entry> hinged;
  std::vector<const constraints::RigidObject*> all_objects;
  std::vector<int> object_systems;
  int max_nv = 6;
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    if (P.objects[i].hinged()) hinged.push_back({&P.objects[i], nm + static_cast<int>(i)});
    all_objects.push_back(&P.objects[i]);
    object_systems.push_back(nm + static_cast<int>(i));
  }
  for (const MannequinModel& mm : model_.mannequins) max_nv = std::max(max_nv, mm.model.nv);
  if (!hinged.empty()) {
    P.hinges = std::make_unique<constraints::HingeLimitRows>(std::move(hinged));
    P.solver->addProducer(P.hinges.get());
  }
  if (!P.objects.empty()) {
    P.guides = std::make_unique<GuideRows>(all_objects, object_systems);
    P.solver->addProducer(P.guides.get());
    P.grasps = std::make_unique<constraints::GraspRows>(std::move(all_objects), std::move(object_systems), max_nv);
    P.solver->addProducer(P.grasps.get());
    P.grasp_records.assign(8, {});  // constraints::GraspRows' default max_grasps
  }
  // balance: the support region of each mannequin's feet, its CoM distance, and (balance_rows) its row
  for (std::size_t m = 0; m < mannequins.size(); ++m) {
    ControllerStepper& cs = *mannequins[m].controller;
    P.balance.push_back(std::make_unique<constraints::BalanceRows>(static_cast<int>(m), model_.mannequins[m].model,
                                                                   cs.controller().data(), pc.balance));
    P.support.emplace_back();
    P.support.back().reserve(static_cast<std::size_t>(pc.balance.max_points));
    if (pc.balance_rows) P.solver->addProducer(P.balance.back().get());
  }
  // the balance controller (Algorithm 5 in the loop): one solver per mannequin, the frames it takes over
  const BalanceControllerConfig& bc = pc.balance_controller;
  if (bc.enabled) {
    for (std::size_t m = 0; m < mannequins.size(); ++m) {
      const MannequinModel& mm = model_.mannequins[m];
      PhysicsData::BalanceLoop L(mm.model);
      L.solver = std::make_unique<balance::VariationalBalanceSolver>(mm.model);
      L.taken.assign(mm.control_frames.size(), 0);
      L.k = skeleton::VectorX::Constant(mm.model.nv, bc.joint_stiffness);
      L.b = skeleton::VectorX::Constant(mm.model.nv, bc.joint_damping);
      L.k.head<6>().setZero();
      L.b.head<6>().setZero();
      for (const int i : mm.balance_frames) L.taken[static_cast<std::size_t>(i)] = 1;
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
  P.stepping.assign(mannequins.size(), 0);
  P.set.contacts.reserve(static_cast<std::size_t>(pc.solver.max_rows));
  data_->contacts.reserve(static_cast<std::size_t>(pc.solver.max_rows));
}

const collision::CollisionWorld* World::collisionWorld() const { return data_->physics ? &data_->physics->cw : nullptr; }
const constraints::ConstraintSolver* World::constraintSolver() const { return data_->physics ? data_->physics->solver.get() : nullptr; }

int World::numObjects() const { return data_->physics ? static_cast<int>(data_->physics->objects.size()) : 0; }
const constraints::RigidObject& World::object(int i) const {
  if (i < 0 || i >= numObjects()) throw std::out_of_range("sim: no object " + std::to_string(i));
  return data_->physics->objects[static_cast<std::size_t>(i)];
}
constraints::RigidObject& World::object(int i) {
  if (i < 0 || i >= numObjects()) throw std::out_of_range("sim: no object " + std::to_string(i));
  return data_->physics->objects[static_cast<std::size_t>(i)];
}
int World::findObject(const std::string& name) const {
  for (int i = 0; i < numObjects(); ++i)
    if (data_->physics->objects[static_cast<std::size_t>(i)].name() == name) return i;
  return -1;
}
int World::objectBody(int i) const {
  (void)object(i);
  return data_->physics->object_body[static_cast<std::size_t>(i)];
}

int World::grasp(int m, const std::string& frame, const std::string& object_name) {
  if (!data_->physics) throw std::invalid_argument("sim: grasp needs physics (physics.enabled)");
  if (m < 0 || m >= numMannequins()) throw std::invalid_argument("sim: grasp: no mannequin " + std::to_string(m));
  const skeleton::Model& model = model_.mannequins[static_cast<std::size_t>(m)].model;
  const int f = model.findFrame(frame);
  if (f < 0) throw std::invalid_argument("sim: grasp: mannequin '" + name(m) + "' has no frame '" + frame + "'");
  const int o = findObject(object_name);
  if (o < 0) throw std::invalid_argument("sim: grasp: no object '" + object_name + "' (movable scene bodies with a mass)");
  PhysicsData& P = *data_->physics;
  constraints::GraspRows::Hand hand;
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
  if (!data_->physics || !data_->physics->grasps || !data_->physics->grasps->release(handle)) return false;
  PhysicsData& P = *data_->physics;
  const PhysicsData::GraspRecord g = P.grasp_records[static_cast<std::size_t>(handle)];
  P.grasp_records[static_cast<std::size_t>(handle)] = {};
  if (g.object >= 0 && g.mannequin >= 0 && !P.holds(g.mannequin, g.object))
    P.cw.setIgnoresMannequin(P.object_body[static_cast<std::size_t>(g.object)], P.cw_mannequin[static_cast<std::size_t>(g.mannequin)], false);
  return true;
}

bool World::objectHeld(int i) const {
  (void)object(i);
  return data_->physics->grasps && data_->physics->grasps->held(i);
}

math::Vector3 World::graspForce(int handle) const {
  if (!data_->physics || !data_->physics->grasps || handle < 0 || static_cast<std::size_t>(handle) >= data_->physics->grasp_records.size() ||
      data_->physics->grasp_records[static_cast<std::size_t>(handle)].object < 0)
    return math::Vector3::Zero();
  return data_->physics->grasps->force(handle);
}

std::vector<GraspState> World::grasps() const {
  std::vector<GraspState> out;
  if (!data_->physics || !data_->physics->grasps) return out;
  for (std::size_t h = 0; h < data_->physics->grasp_records.size(); ++h) {
    const PhysicsData::GraspRecord& g = data_->physics->grasp_records[h];
    if (g.object < 0) continue;
    out.push_back({static_cast<int>(h), g.mannequin, g.joint, g.object, data_->physics->grasps->force(static_cast<int>(h))});
  }
  return out;
}

std::array<math::Vector3, 2> World::handForces(int m) const {
  std::array<math::Vector3, 2> out{math::Vector3::Zero(), math::Vector3::Zero()};
  if (!data_->physics || m < 0 || m >= numMannequins()) return out;
  const PhysicsData& P = *data_->physics;
  const skeleton::Model& model = model_.mannequins[static_cast<std::size_t>(m)].model;
  std::array<int, 2> hand{-1, -1};  // the joints carrying the hand segments
  for (const skeleton::Segment& s : model.segments) {
    if (s.name == "hand_l") hand[0] = s.joint;
    if (s.name == "hand_r") hand[1] = s.joint;
  }
  for (int side = 0; side < 2; ++side) {
    if (hand[static_cast<std::size_t>(side)] < 0) continue;
    math::Vector3& f = out[static_cast<std::size_t>(side)];
    for (std::size_t h = 0; h < P.grasp_records.size(); ++h) {
      const PhysicsData::GraspRecord& g = P.grasp_records[h];
      if (g.object >= 0 && g.mannequin == m && g.joint == hand[static_cast<std::size_t>(side)])
        f -= P.grasps->force(static_cast<int>(h));
    }
    const auto isHand = [&](int body) {
      return body >= 0 && static_cast<std::size_t>(body) < P.body_mannequin.size() &&
             P.body_mannequin[static_cast<std::size_t>(body)] == m &&
             P.body_joint[static_cast<std::size_t>(body)] == hand[static_cast<std::size_t>(side)];
    };
    for (const ContactReport& c : data_->contacts) {  // n from a to b: a gets −λ n, b gets +λ n
      if (isHand(c.body_a)) f -= c.normal_force * c.normal;
      if (isHand(c.body_b)) f += c.normal_force * c.normal;
    }
  }
  return out;
}

void World::kineticsInputs(int m, std::vector<kinetics::ContactPoint>& contacts, std::vector<kinetics::Load>& loads) const {
  contacts.clear();
  loads.clear();
  if (!data_->physics || m < 0 || m >= numMannequins()) return;
  const PhysicsData& P = *data_->physics;
  const skeleton::Data& d = data(m);
  const auto mannequinOf = [&](int body) {
    return body >= 0 && static_cast<std::size_t>(body) < P.body_mannequin.size() ? P.body_mannequin[static_cast<std::size_t>(body)] : -1;
  };
  for (const ContactReport& c : data_->contacts) {  // n from a to b: the other body pushes a along −n, b along +n
    if (!(c.normal_force > 0 || c.distance <= 0)) continue;
    const bool on_a = mannequinOf(c.body_a) == m, on_b = mannequinOf(c.body_b) == m;
    if (on_a == on_b) continue;  // not on m, or between two of its own segments (internal)
    const int body = on_a ? c.body_a : c.body_b;
    kinetics::ContactPoint p;
    p.point = c.point;
    p.normal = on_a ? math::Vector3(-c.normal) : c.normal;
    p.mu = P.contacts ? P.contacts->friction(c.body_a, c.body_b) : 0.0;
    p.joint = P.body_joint[static_cast<std::size_t>(body)];
    contacts.push_back(p);
  }
  for (std::size_t h = 0; h < P.grasp_records.size(); ++h) {
    const PhysicsData::GraspRecord& g = P.grasp_records[h];
    if (g.object < 0 || g.mannequin != m || g.joint < 0) continue;
    loads.push_back(kinetics::Load{g.joint, d.oMi[static_cast<std::size_t>(g.joint)].p, -P.grasps->force(static_cast<int>(h))});
  }
}

void World::attachGuide(int i, const control::MechanismSpec& spec) {
  if (!data_->physics || !data_->physics->guides) throw std::invalid_argument("sim: a guide needs physics and a scene with objects");
  data_->physics->guides->attach(i, spec);
}

bool World::detachGuide(int i) { return data_->physics && data_->physics->guides && data_->physics->guides->detach(i); }

const GuideRows* World::guides() const { return data_->physics ? data_->physics->guides.get() : nullptr; }

}  // namespace mannequin::sim
