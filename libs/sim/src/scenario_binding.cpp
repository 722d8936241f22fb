// A scenario in the World's loop (World::setScenario): where its frames and objects are, its
// observation each step, its actions and setpoints applied to the mannequins.
#include "world_state.hpp"

namespace mannequin::sim {

void World::setScenario(scenario::Scenario sc) {
  auto run = std::make_unique<ScenarioRun>();
  const std::string where = "sim: scenario '" + sc.name + "'";
  for (const scenario::FrameRef& f : sc.frames) {
    int m = -1;
    for (int k = 0; k < numMannequins(); ++k)
      if (name(k) == f.mannequin) m = k;
    if (m < 0) throw std::invalid_argument(where + ": no mannequin '" + f.mannequin + "' in the World");
    const MannequinModel& mm = model_.mannequins[static_cast<std::size_t>(m)];
    std::size_t driven = mm.control_frames.size();
    for (std::size_t i = 0; i < mm.control_frames.size(); ++i)
      if (mm.control_frames[i].frame == f.frame) driven = i;
    if (driven == mm.control_frames.size())
      throw std::invalid_argument(where + ": mannequin '" + f.mannequin + "' has no control frame '" + f.frame +
                                  "' driven by mocap (the sim config's control_frames)");
    ScenarioRun::Frame fr{m, driven, mm.model.frames[static_cast<std::size_t>(mm.frame_indices[driven])].joint, {}};
    std::vector<char> control_joint(mm.model.joints.size(), 0);
    for (const int fi : mm.frame_indices) control_joint[static_cast<std::size_t>(mm.model.frames[static_cast<std::size_t>(fi)].joint)] = 1;
    fr.force_joints.assign(mm.model.joints.size(), 0);
    for (std::size_t j = 0; j < mm.model.joints.size(); ++j) {
      int a = static_cast<int>(j);
      while (a >= 0 && !control_joint[static_cast<std::size_t>(a)]) a = mm.model.joints[static_cast<std::size_t>(a)].parent;
      fr.force_joints[j] = a == fr.joint;
    }
    run->frames.push_back(std::move(fr));
  }
  for (const scenario::ObjectDecl& o : sc.objects) {
    const int k = data_->physics ? findObject(o.name) : -1;
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
  if (data_->scenario) {
    // the previous scenario's effects end with it: its mechanisms off, its grasps released, modes free
    // (gains it set stay)
    ScenarioRun& S = *data_->scenario;
    for (std::size_t i = 0; i < S.frames.size(); ++i) {
      MannequinData& m = data_->mannequins[static_cast<std::size_t>(S.frames[i].mannequin)];
      if (S.mechanism[i] != nullptr)
        if (ControllerStepper* cs = m.controller) cs->setMechanism(static_cast<int>(S.frames[i].driven), nullptr);
      if (S.grasp_handle[i] >= 0) release(S.grasp_handle[i]);
      m.frames[S.frames[i].driven].mode = "free";
    }
    for (std::size_t k = 0; k < S.objects.size(); ++k)
      if (S.guided[k]) detachGuide(S.objects[k]);
  }
  data_->scenario = std::move(run);
}

void World::trigger(const std::string& name, const std::string& value) {
  if (data_->scenario) data_->scenario->pending.push_back({name, value});
}

const scenario::Engine* World::scenarioEngine() const { return data_->scenario ? data_->scenario->engine.get() : nullptr; }
long World::scenarioUnappliedActions() const { return data_->scenario ? data_->scenario->unapplied : 0; }

void World::stepScenario() {
  ScenarioRun& S = *data_->scenario;
  for (const ScenarioRun::Frame& f : S.frames)
    if (!data_->mannequins[static_cast<std::size_t>(f.mannequin)].calibrated) {
      S.pending.clear();  // not running yet: triggers are dropped, not queued for its first step
      return;
    }
  scenario::Observation& obs = S.obs;
  obs.time = time();
  for (std::size_t i = 0; i < S.frames.size(); ++i) {
    const DrivenFrame& st = data_->mannequins[static_cast<std::size_t>(S.frames[i].mannequin)].frames[S.frames[i].driven];
    obs.frames[i].pose = st.actual;
    obs.frames[i].target = st.target;  // the mocap target driveTargets just set
    obs.frames[i].force.setZero();
    if (S.grasp_handle[i] >= 0) obs.frames[i].force = -graspForce(S.grasp_handle[i]);  // the object's pull on the hand
  }
  if (data_->physics) {
    // the contact forces of the last step on each commanded frame's segments (normal forces: the friction
    // rows' directions are not reported); a contact's force on body a is −λ n (n from a to b)
    const PhysicsData& P = *data_->physics;
    for (const ContactReport& c : data_->contacts)
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
    const constraints::RigidObject& o = object(S.objects[k]);
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
    if (act.kind == scenario::Action::Kind::kGrasp && frame_ok && act.object >= 0 && data_->physics) {
      const ScenarioRun::Frame& f = S.frames[static_cast<std::size_t>(act.frame)];
      int& held = S.grasp_handle[static_cast<std::size_t>(act.frame)];
      if (held >= 0) release(held);  // one grasp per frame: a second one replaces the first
      held =
          grasp(f.mannequin, sc.frames[static_cast<std::size_t>(act.frame)].frame, sc.objects[static_cast<std::size_t>(act.object)].name);
    } else if (act.kind == scenario::Action::Kind::kSetGains && frame_ok) {
      const ScenarioRun::Frame& f = S.frames[static_cast<std::size_t>(act.frame)];
      ControllerStepper* cs = data_->mannequins[static_cast<std::size_t>(f.mannequin)].controller;
      if (cs == nullptr) {
        ++S.unapplied;  // the kinematic tracker has no gains to set
      } else {
        try {
          cs->setGains(static_cast<int>(f.driven), act.stiffness ? &*act.stiffness : nullptr, act.damping ? &*act.damping : nullptr);
        } catch (const std::invalid_argument&) {
          ++S.unapplied;  // bad gains are refused at load: not expected
        }
      }
    } else if (act.kind == scenario::Action::Kind::kAttachGuide && act.object >= 0 && act.mechanism && data_->physics) {
      const std::size_t k = static_cast<std::size_t>(act.object);
      try {
        attachGuide(S.objects[k], act.mechanism->spec);
        S.guided[k] = 1;
      } catch (const std::invalid_argument&) {
        ++S.unapplied;  // validated at setScenario: not expected
      }
    } else if (act.kind == scenario::Action::Kind::kDetachGuide && act.object >= 0 && data_->physics) {
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
    MannequinData& m = data_->mannequins[static_cast<std::size_t>(S.frames[i].mannequin)];
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
      ControllerStepper* cs = m.controller;
      try {
        if (cs != nullptr) cs->setMechanism(static_cast<int>(S.frames[i].driven), mech);
      } catch (const std::invalid_argument&) {
        ++S.unapplied;  // validated at load: not expected
      }
      S.mechanism[i] = mech;
    }
  }
}

}  // namespace mannequin::sim
