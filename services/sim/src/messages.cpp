#include "mannequin/simservice/messages.hpp"

#include <cmath>

#include "mannequin/lcp/lcp.hpp"
#include "mannequin/transport/convert.hpp"

namespace mannequin::simservice {

using transport::toMsg;

namespace {

const char* solverName(constraints::SolverUsed s) {
  switch (s) {
    case constraints::SolverUsed::kNone: return "none";
    case constraints::SolverUsed::kLemke: return "lemke";
    case constraints::SolverUsed::kStructured: return "structured";
    case constraints::SolverUsed::kPgs: return "pgs";
    case constraints::SolverUsed::kFailed: return "failed";
  }
  return "?";
}

void toMsg3(const math::Vector3& v, v1::Vec3& out) {
  out.set_x(v.x());
  out.set_y(v.y());
  out.set_z(v.z());
}

// Wall times are left at 0 in replay mode: the same frames give the same sim.world bytes.
void toDiagnostics(const sim::StepDiagnostics& d, bool replay, v1::StepDiagnostics& out) {
  out.set_contacts(d.contacts);
  out.set_active_contacts(d.active_contacts);
  out.set_max_penetration_m(d.max_penetration_m);
  out.set_solver(solverName(d.solver.solver));
  out.set_lemke_status(lcp::statusName(d.solver.lemke_status));
  out.set_rows(d.solver.rows);
  out.set_lcp_size(d.solver.lcp_size);
  out.set_pivots(d.solver.pivots);
  out.set_fallback(d.solver.fallback);
  out.set_dropped_rows(d.solver.dropped);
  out.set_nan(d.nan);
  if (replay) return;
  out.set_collision_s(d.collision_s);
  out.set_free_motion_s(d.free_motion_s);
  out.set_constraints_s(d.constraints_s);
  out.set_integrate_s(d.integrate_s);
  out.set_produce_s(d.solver.produce_s);
  out.set_assemble_s(d.solver.assemble_s);
  out.set_solve_s(d.solver.solve_s);
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

}  // namespace

void toWorldState(const sim::World& world, const v1::ContactSet* contacts, bool stale, bool replay, v1::WorldState& out) {
  out.Clear();
  const double t = world.time();
  out.mutable_header()->set_stamp_ns(static_cast<std::int64_t>(std::llround(t * 1e9)));
  out.set_step(world.stepCount());
  out.set_sim_time(t);
  out.set_mode(replay ? "replay" : "live");
  out.set_contacts_stale(stale);
  if (contacts != nullptr) out.set_contacts_step(contacts->step());
  const collision::CollisionWorld* cw = world.physics() ? world.collisionWorld() : nullptr;
  if (cw != nullptr) toDiagnostics(world.diagnostics(), replay, *out.mutable_diagnostics());
  const sim::MocapGlitches& g = world.mocapGlitches();
  v1::MocapGlitches& gm = *out.mutable_mocap_glitches();
  gm.set_duplicate_frames(g.duplicate_frames);
  gm.set_out_of_order_frames(g.out_of_order_frames);
  gm.set_capture_restarts(g.capture_restarts);
  gm.set_non_finite_bodies(g.non_finite_bodies);
  gm.set_occlusions(g.occlusions);
  gm.set_target_jumps(g.target_jumps);
  gm.set_stream_gaps(g.stream_gaps);
  gm.set_pose_jumps(g.pose_jumps);
  const auto frameRef = [](const mocap::Frame& m, const std::string& source, v1::FrameRef& r) {
    r.set_sequence(m.sequence);
    r.set_stamp_ns(m.stamp_ns);
    r.set_send_time_ns(m.send_time_ns);
    r.set_frame_number(m.frame_number);
    r.set_source(source);
  };
  const std::vector<std::string> sources = world.mocapSources();
  for (const std::string& src : sources)
    if (const mocap::Frame* m = world.latestMocap(src)) {
      frameRef(*m, src, *out.add_mocap_sources());
      if (!out.has_mocap()) frameRef(*m, src, *out.mutable_mocap());
    }
  for (int i = 0; i < world.numObjects(); ++i) {
    const constraints::RigidObject& o = world.object(i);
    v1::ObjectState* os = out.add_objects();
    os->set_name(o.name());
    toMsg(o.pose(), *os->mutable_pose());
    for (Eigen::Index k = 0; k < o.velocity().size(); ++k) os->add_twist(o.velocity()(k));
    os->set_hinged(o.hinged());
    os->set_angle(o.angle());
    toMsg3(o.pointVelocity(o.pose().p), *os->mutable_velocity());
    os->set_held(world.objectHeld(i));
  }
  for (int i = 0; i < world.numMannequins(); ++i) {
    const skeleton::Model& model = world.model(i);
    const skeleton::Data& d = world.data(i);
    v1::MannequinState* ms = out.add_mannequins();
    ms->set_name(world.name(i));
    ms->set_model(model.name);
    ms->set_calibrated(world.calibrated(i));
    for (int k = 0; k < model.nq; ++k) ms->add_q(world.q(i)(k));
    for (int k = 0; k < model.nv; ++k) ms->add_v(world.qdot(i)(k));
    for (const skeleton::Segment& s : model.segments) {
      v1::NamedPose* np = ms->add_segments();
      np->set_name(s.name);
      toMsg(d.oMi[s.joint], *np->mutable_pose());
    }
    toMsg(d.com, *ms->mutable_com());
    for (const sim::DrivenFrame& st : world.controlFrames(i)) {
      v1::ControlFrameState* c = ms->add_control_frames();
      c->set_frame(st.frame);
      c->set_body(st.body);
      c->set_mode(st.mode);
      toMsg(st.target, *c->mutable_target());
      toMsg(st.actual, *c->mutable_actual());
      c->set_position_error(st.position_error);
      c->set_orientation_error(st.orientation_error);
      c->set_tracked(st.tracked);
      c->set_weight(st.weight);
    }
    ms->set_port_energy(world.stepper(i).portEnergy());
    if (cw != nullptr) {
      const sim::MannequinDiagnostics& md = world.mannequinDiagnostics(i);
      ms->set_balance_distance(md.balance_distance_m);
      ms->set_contact_count(md.contacts);
      ms->set_foot_contact(md.foot_contact);
      ms->set_sole_height(md.sole_height_m);
      ms->set_worst_joint_limit_excess(md.worst_joint_limit_excess_rad);
      ms->set_force_margin(md.force_margin_n);
      ms->set_balance_driving(md.balance_driving);
      ms->set_balance_margin_fraction(md.balance_margin_fraction);
      // the World's contacts touching this mannequin's segments (bodies "<name>/<segment>")
      const std::string prefix = world.name(i) + "/";
      for (const sim::ContactReport& k : world.contacts()) {
        const std::string& a = cw->bodyName(k.body_a);
        const std::string& b = cw->bodyName(k.body_b);
        if (!startsWith(a, prefix) && !startsWith(b, prefix)) continue;
        v1::ContactPoint* p = ms->add_contacts();
        p->set_body_a(a);
        p->set_body_b(b);
        toMsg3(k.normal, *p->mutable_normal());
        p->set_distance(k.distance);
        toMsg3(-k.normal_force * k.normal, *p->mutable_force());
        toMsg3(k.point, *p->mutable_point());
        p->set_normal_force(k.normal_force);
        p->set_friction_force(k.friction_force);
      }
      continue;  // the physics' contacts, not the collision service's
    }
    ms->set_balance_distance(NAN);
    ms->set_sole_height(NAN);
    ms->set_force_margin(NAN);
    if (contacts != nullptr)
      for (const v1::Contact& k : contacts->contacts()) {
        if (k.mannequin_a() != world.name(i) && k.mannequin_b() != world.name(i)) continue;
        v1::ContactPoint* p = ms->add_contacts();
        p->set_body_a(k.mannequin_a().empty() ? k.body_a() : k.mannequin_a() + "/" + k.body_a());
        p->set_body_b(k.mannequin_b().empty() ? k.body_b() : k.mannequin_b() + "/" + k.body_b());
        *p->mutable_point_a() = k.point_a_world();
        *p->mutable_point_b() = k.point_b_world();
        *p->mutable_normal() = k.normal();
        p->set_distance(k.distance());
      }
  }
}

void toCollisionQuery(const sim::World& world, double margin, v1::CollisionQuery& out) {
  out.Clear();
  out.mutable_header()->set_stamp_ns(static_cast<std::int64_t>(std::llround(world.time() * 1e9)));
  out.set_step(world.stepCount());
  out.set_margin(margin);
  for (int i = 0; i < world.numMannequins(); ++i) {
    v1::MannequinConfiguration* m = out.add_mannequins();
    m->set_name(world.name(i));
    for (int k = 0; k < world.model(i).nq; ++k) m->add_q(world.q(i)(k));
  }
}

void toScenarioState(const scenario::Engine& engine, double sim_time, v1::ScenarioState& out) {
  out.Clear();
  out.mutable_header()->set_stamp_ns(static_cast<std::int64_t>(std::llround(sim_time * 1e9)));
  out.set_scenario(engine.scenario().name);
  out.set_state(engine.stateName());
  out.set_time_in_state(engine.timeInState());
  for (const std::string& s : engine.contextStack()) out.add_context_stack(s);
  for (const std::string& s : engine.lastEvents()) out.add_last_events(s);
}

ScenarioWatch::Tick ScenarioWatch::after(const sim::World& world) {
  Tick t;
  const scenario::Engine* e = world.scenarioEngine();
  if (e == nullptr || e->state() < 0) return t;
  t.engine = e;
  t.switched = e->state() != last_state_;
  t.first = t.switched && last_state_ < 0;
  last_state_ = e->state();
  phase_ += per_step_;
  const bool scheduled = phase_ >= 1.0 - 1e-9;
  if (scheduled) phase_ -= 1.0;
  t.publish = scheduled || t.switched;
  return t;
}

std::string ScenarioWatch::events(const scenario::Engine& engine) {
  std::string out;
  for (const std::string& l : engine.lastEvents()) out += (out.empty() ? "" : "; ") + l;
  return out;
}

}  // namespace mannequin::simservice
