#include "mannequin/simservice/messages.hpp"

#include <cmath>

#include "mannequin/transport/convert.hpp"

namespace mannequin::simservice {

using transport::toMsg;

void toWorldState(const sim::World& world, const v1::ContactSet* contacts, bool stale, bool replay, v1::WorldState& out) {
  out.Clear();
  const double t = world.time();
  out.mutable_header()->set_stamp_ns(static_cast<std::int64_t>(std::llround(t * 1e9)));
  out.set_step(world.stepCount());
  out.set_sim_time(t);
  out.set_mode(replay ? "replay" : "live");
  out.set_contacts_stale(stale);
  if (contacts != nullptr) out.set_contacts_step(contacts->step());
  if (const mocap::Frame* m = world.latestMocap()) {
    v1::FrameRef* r = out.mutable_mocap();
    r->set_sequence(m->sequence);
    r->set_stamp_ns(m->stamp_ns);
    r->set_send_time_ns(m->send_time_ns);
    r->set_frame_number(m->frame_number);
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
      c->set_mode("free");
      toMsg(st.target, *c->mutable_target());
      toMsg(st.actual, *c->mutable_actual());
      c->set_position_error(st.position_error);
      c->set_orientation_error(st.orientation_error);
      c->set_tracked(st.tracked);
      c->set_weight(st.weight);
    }
    ms->set_balance_distance(NAN);
    ms->set_port_energy(world.stepper(i).portEnergy());
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

}  // namespace mannequin::simservice
