// A World's checkpoint and its restore (a restarted sim resuming where it was).
#include "world_state.hpp"

namespace mannequin::sim {

namespace {
bool finiteSE3(const math::SE3& T) {
  return T.p.allFinite() && T.R.allFinite() && (T.R.transpose() * T.R - math::Matrix3::Identity()).norm() < 1e-6 &&
         T.R.determinant() > 0;
}
}  // namespace

WorldCheckpoint World::checkpoint() const {
  WorldCheckpoint c;
  c.step = data_->steps;
  for (std::size_t k = 0; k < data_->mannequins.size(); ++k) {
    const MannequinData& m = data_->mannequins[k];
    MannequinCheckpoint mc;
    mc.name = model_.mannequins[k].name;
    mc.model = model_.mannequins[k].model.name;
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
    const constraints::RigidObject& o = object(i);
    c.objects.push_back({o.name(), o.hinged(), o.pose(), o.angle()});
  }
  return c;
}

std::vector<std::string> World::restore(const WorldCheckpoint& c) {
  // everything checked first: a refused checkpoint leaves the World as it was
  const auto fail = [](const std::string& what) { throw std::invalid_argument("sim: checkpoint: " + what); };
  const std::size_t nm = data_->mannequins.size();
  if (c.mannequins.size() != nm) {
    std::string names;
    for (const MannequinCheckpoint& mc : c.mannequins) names += (names.empty() ? "" : ", ") + mc.name;
    fail("it has " + std::to_string(c.mannequins.size()) + " mannequin(s) (" + names + "), the World " +
         std::to_string(nm));
  }
  std::vector<const MannequinCheckpoint*> of(nm, nullptr);
  for (std::size_t k = 0; k < nm; ++k) {
    const MannequinModel& mm = model_.mannequins[k];
    const MannequinData& m = data_->mannequins[k];
    for (const MannequinCheckpoint& mc : c.mannequins)
      if (mc.name == mm.name) of[k] = &mc;
    if (of[k] == nullptr) fail("no mannequin '" + mm.name + "'");
    const MannequinCheckpoint& mc = *of[k];
    const std::string who = "mannequin '" + mm.name + "': ";
    if (mc.model != mm.model.name) fail(who + "model '" + mc.model + "', the World's is '" + mm.model.name + "'");
    if (mc.q.size() != mm.model.nq) fail(who + "q has " + std::to_string(mc.q.size()) + " coordinates, the model " + std::to_string(mm.model.nq));
    if (!mc.q.allFinite()) fail(who + "q is not finite");
    if (!mc.calibrated) continue;
    if (mc.q_posture.size() != mm.model.nq || !mc.q_posture.allFinite()) fail(who + "the posture target q_c is not " + std::to_string(mm.model.nq) + " finite numbers");
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
    const constraints::RigidObject& o = object(i);
    for (const ObjectCheckpoint& oc : c.objects)
      if (oc.name == o.name()) obj[static_cast<std::size_t>(i)] = &oc;
    const ObjectCheckpoint* oc = obj[static_cast<std::size_t>(i)];
    if (oc == nullptr) fail("no object '" + o.name() + "'");
    if (oc->hinged != o.hinged()) fail("object '" + o.name() + "': hinged in one, free in the other");
    if (o.hinged() ? !std::isfinite(oc->angle) : !finiteSE3(oc->pose)) fail("object '" + o.name() + "': its pose is not finite");
  }
  // apply
  std::vector<std::string> notes;
  data_->steps = c.step;
  for (std::size_t k = 0; k < nm; ++k) {
    MannequinData& m = data_->mannequins[k];
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
    if (data_->physics) {
      data_->physics->cw.setMannequinPlaced(data_->physics->cw_mannequin[k], mc.calibrated);
      if (!data_->physics->balance_loops.empty()) {
        if (data_->physics->balance_loops[k].driving) notes.push_back("mannequin '" + model_.mannequins[k].name + "': the balance controller starts again from q");
        data_->physics->balance_loops[k].driving = false;
      }
    }
  }
  for (int i = 0; i < numObjects(); ++i) {
    constraints::RigidObject& o = object(i);
    const ObjectCheckpoint& oc = *obj[static_cast<std::size_t>(i)];
    if (o.hinged()) o.setAngle(oc.angle);
    else o.setPose(oc.pose);
  }
  return notes;
}

}  // namespace mannequin::sim
