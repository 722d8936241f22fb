#include "mannequin/scenario/engine.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mannequin::scenario {

const char* toString(Phase phase) {
  switch (phase) {
    case Phase::kConfigure: return "configure";
    case Phase::kStart: return "start";
    case Phase::kRun: return "run";
    case Phase::kTeardown: return "teardown";
  }
  return "?";
}

namespace {

void collectEdges(const Condition& c, std::vector<const Condition*>& out) {
  if (c.memory >= 0) out.push_back(&c);
  for (const auto& child : c.children) collectEdges(child, out);
}

// world twist (ω, v) moving pose a to pose b in dt
Vector6 finiteTwist(const SE3& a, const SE3& b, double dt) {
  Vector6 V = Vector6::Zero();
  if (dt <= 0.0) return V;
  V.head<3>() = math::logSO3(b.R * a.R.transpose()) / dt;
  V.tail<3>() = (b.p - a.p) / dt;
  return V;
}

bool compare(double value, const Condition& c) { return c.above ? value > c.threshold : value < c.threshold; }

}  // namespace

Engine::Engine(Scenario scenario) : s_(std::move(scenario)) {
  const std::size_t nf = s_.frames.size();
  mechanisms_.resize(s_.states.size());
  for (std::size_t i = 0; i < s_.states.size(); ++i) {
    mechanisms_[i].resize(nf);
    for (std::size_t f = 0; f < nf; ++f) {
      const ModeSpec& m = s_.states[i].modes[f];
      if (m.mode == ControlMode::kConstrained)
        mechanisms_[i][f] = std::make_unique<control::VirtualMechanism>(m.mechanism->spec);
    }
    for (const auto& t : s_.states[i].transitions) collectEdges(t.when, edge_conditions_);
  }
  for (const auto& t : s_.interrupts) collectEdges(t.when, edge_conditions_);
  inside_prev_.assign(static_cast<std::size_t>(s_.memory_slots), 0);
  inside_now_.assign(static_cast<std::size_t>(s_.memory_slots), 0);
  frames_.resize(nf);
  result_.frames.resize(nf);
  std::size_t entry = 0, exit = 0;
  for (const auto& st : s_.states) {
    entry = std::max(entry, st.entry.size());
    exit = std::max(exit, st.exit.size());
  }
  result_.actions.reserve(entry + exit);
  result_.phases.reserve(8);
  stack_.reserve(8);
  last_events_.reserve(4);
}

std::vector<std::string> Engine::lastEvents() const {
  std::vector<std::string> labels;
  for (const Transition* t : last_events_) labels.push_back(t->label);
  return labels;
}

std::vector<std::string> Engine::contextStack() const {
  std::vector<std::string> names;
  for (const auto& c : stack_) names.push_back(s_.states[static_cast<std::size_t>(c.state)].name);
  return names;
}

bool Engine::eval(const Condition& c, const Observation& obs) const {
  using K = Condition::Kind;
  const auto frame = [&](int i) -> const FrameObservation& { return obs.frames[static_cast<std::size_t>(i)]; };
  switch (c.kind) {
    case K::kInside: return c.zone.contains(frame(c.frame).pose.p);
    case K::kOutside: return !c.zone.contains(frame(c.frame).pose.p);
    case K::kEnter: {
      const auto m = static_cast<std::size_t>(c.memory);
      return inside_now_[m] && !inside_prev_[m];
    }
    case K::kLeave: {
      const auto m = static_cast<std::size_t>(c.memory);
      return !inside_now_[m] && inside_prev_[m];
    }
    case K::kDistance: {
      const Vector3 to = c.other_frame >= 0 ? frame(c.other_frame).pose.p
                         : c.object >= 0    ? obs.objects[static_cast<std::size_t>(c.object)].pose.p
                                            : c.point;
      return compare((frame(c.frame).pose.p - to).norm(), c);
    }
    case K::kForce: return compare(frame(c.frame).force.norm(), c);
    case K::kReached: {
      SE3 goal;
      if (c.pose) {
        goal = c.object >= 0 ? obs.objects[static_cast<std::size_t>(c.object)].pose * *c.pose : *c.pose;
      } else {
        goal = frames_[static_cast<std::size_t>(c.frame)].goal;
      }
      const SE3& H = frame(c.frame).pose;
      return (H.p - goal.p).norm() <= c.tolerance_m && math::logSO3(goal.R.transpose() * H.R).norm() <= c.tolerance_rad;
    }
    case K::kTime: return time_in_state_ >= c.threshold;
    case K::kObject: {
      const auto& o = obs.objects[static_cast<std::size_t>(c.object)];
      return compare(o.values[static_cast<std::size_t>(c.value_index)], c);
    }
    case K::kTrigger:
      for (const auto& t : obs.triggers)
        if (t.name == c.trigger && (c.trigger_value.empty() || t.value == c.trigger_value)) return true;
      return false;
    case K::kAll:
      for (const auto& child : c.children)
        if (!eval(child, obs)) return false;
      return true;
    case K::kAny:
      for (const auto& child : c.children)
        if (eval(child, obs)) return true;
      return false;
    case K::kNot: return !eval(c.children[0], obs);
  }
  return false;
}

Setpoint Engine::rawSetpoint(std::size_t f, const SE3& target) const {
  Setpoint sp;
  const auto st = static_cast<std::size_t>(state_);
  switch (s_.states[st].modes[f].mode) {
    case ControlMode::kFree: sp.pose = target; break;
    case ControlMode::kConstrained: {
      const auto& mech = *mechanisms_[st][f];
      sp.pose = mech.poseAt(mech.project(target));
      break;
    }
    case ControlMode::kAutonomous: sp = frames_[f].trajectory.sample(0); break;  // unused
  }
  return sp;
}

// the current mode's own setpoint now, its twist by a finite difference over the previous target
Setpoint Engine::modeSetpoint(std::size_t f, const Observation& obs, double dt) const {
  const FrameState& fs = frames_[f];
  const ModeSpec& m = s_.states[static_cast<std::size_t>(state_)].modes[f];
  if (m.mode == ControlMode::kAutonomous) return fs.trajectory.sample(obs.time - fs.start_time);
  Setpoint sp = rawSetpoint(f, obs.frames[f].target);
  if (fs.has_setpoint) sp.twist = finiteTwist(rawSetpoint(f, fs.prev_target).pose, sp.pose, dt);
  return sp;
}

void Engine::enter(int state, const Observation& obs, bool fresh, double time_in_state) {
  state_ = state;
  const State& st = s_.states[static_cast<std::size_t>(state)];
  const double dt = started_ ? obs.time - prev_time_ : 0.0;
  if (fresh) {
    result_.phases.emplace_back(state, Phase::kConfigure);
    for (std::size_t f = 0; f < frames_.size(); ++f) {
      const ModeSpec& m = st.modes[f];
      if (m.mode == ControlMode::kAutonomous)
        frames_[f].goal = m.relative_to >= 0 ? obs.objects[static_cast<std::size_t>(m.relative_to)].pose * m.goal : m.goal;
    }
    for (const Action& a : st.entry) result_.actions.push_back({&a, state, true});
  }
  result_.phases.emplace_back(state, Phase::kStart);
  for (std::size_t f = 0; f < frames_.size(); ++f) {
    FrameState& fs = frames_[f];
    const ModeSpec& m = st.modes[f];
    fs.start_time = obs.time;
    fs.blending = false;
    if (m.mode == ControlMode::kAutonomous) {
      Setpoint from = fs.setpoint;
      if (!fs.has_setpoint) from = Setpoint{obs.frames[f].target, Vector6::Zero()};
      fs.trajectory = MinimumJerkTrajectory(from, fs.goal, m.duration);
    } else if (fs.has_setpoint) {
      // Fig. 4.5: from the setpoint at the switch onto the new mode's own setpoint
      fs.blend = Blend(fs.setpoint, modeSetpoint(f, obs, dt), m.blend);
      fs.blending = true;
    }
  }
  active_since_ = obs.time;
  time_offset_ = time_in_state;
  time_in_state_ = time_in_state;
}

void Engine::leave(bool teardown) {
  if (!teardown) return;
  result_.phases.emplace_back(state_, Phase::kTeardown);
  for (const Action& a : s_.states[static_cast<std::size_t>(state_)].exit) result_.actions.push_back({&a, state_, false});
}

const StepResult& Engine::step(const Observation& obs) {
  if (obs.frames.size() != s_.frames.size())
    throw std::invalid_argument("scenario '" + s_.name + "': observation has " + std::to_string(obs.frames.size()) +
                                " frames, the scenario commands " + std::to_string(s_.frames.size()));
  if (obs.objects.size() != s_.objects.size())
    throw std::invalid_argument("scenario '" + s_.name + "': observation has " + std::to_string(obs.objects.size()) +
                                " objects, the scenario declares " + std::to_string(s_.objects.size()));
  for (std::size_t i = 0; i < obs.objects.size(); ++i)
    if (obs.objects[i].values.size() != s_.objects[i].values.size())
      throw std::invalid_argument("scenario '" + s_.name + "': object '" + s_.objects[i].name + "' has " +
                                  std::to_string(obs.objects[i].values.size()) + " values, expected " +
                                  std::to_string(s_.objects[i].values.size()));
  if (!std::isfinite(obs.time))
    throw std::invalid_argument("scenario '" + s_.name + "': the observation's time is not finite");
  if (started_ && !(obs.time >= prev_time_))
    throw std::invalid_argument("scenario '" + s_.name + "': time went back (" + std::to_string(obs.time) + " s after " +
                                std::to_string(prev_time_) + " s)");
  result_.switched = false;
  result_.actions.clear();
  result_.phases.clear();
  result_.unknown_triggers.clear();
  for (const auto& t : obs.triggers)
    if (s_.triggerIndex(t.name) < 0) result_.unknown_triggers.push_back(t.name);

  // zone memories: no edge on the first step
  for (const Condition* c : edge_conditions_)
    inside_now_[static_cast<std::size_t>(c->memory)] = c->zone.contains(obs.frames[static_cast<std::size_t>(c->frame)].pose.p);
  if (!started_) inside_prev_ = inside_now_;

  const double dt = started_ ? obs.time - prev_time_ : 0.0;
  if (!started_) {
    enter(s_.initial, obs, true, 0.0);
  }
  time_in_state_ = time_offset_ + (obs.time - active_since_);

  // (a) the current modes' setpoints now: what a switch starts from
  for (std::size_t f = 0; f < frames_.size(); ++f) {
    FrameState& fs = frames_[f];
    Setpoint sp = modeSetpoint(f, obs, dt);
    if (fs.blending) {
      sp = fs.blend.apply(obs.time - fs.start_time, sp);
      fs.blending = fs.blend.active(obs.time - fs.start_time);
    }
    fs.setpoint = sp;
    fs.has_setpoint = true;
  }

  // (b) run: interrupts, then the state's transitions; one fires at most
  result_.phases.emplace_back(state_, Phase::kRun);
  const Transition* fired = nullptr;
  for (const Transition& t : s_.interrupts) {
    if (t.to == state_) continue;
    bool stacked = false;
    for (const auto& c : stack_) stacked = stacked || c.state == t.to;
    if (!stacked && eval(t.when, obs)) {
      fired = &t;
      break;
    }
  }
  if (fired == nullptr) {
    for (const Transition& t : s_.states[static_cast<std::size_t>(state_)].transitions) {
      if (t.resume && stack_.empty()) continue;
      if (t.urgent) {
        bool stacked = false;
        for (const auto& c : stack_) stacked = stacked || c.state == t.to;
        if (stacked) continue;
      }
      if (eval(t.when, obs)) {
        fired = &t;
        break;
      }
    }
  }

  // (c) switch: the new modes start from the setpoints of (a)
  if (fired != nullptr) {
    result_.switched = true;
    last_events_.clear();
    last_events_.push_back(fired);
    if (fired->resume) {
      leave(true);
      const Context back = stack_.back();
      stack_.pop_back();
      enter(back.state, obs, false, back.time_in_state);
    } else if (fired->urgent) {
      stack_.push_back({state_, time_in_state_});
      leave(false);
      enter(fired->to, obs, true, 0.0);
    } else {
      leave(true);
      enter(fired->to, obs, true, 0.0);
    }
  }

  for (std::size_t f = 0; f < frames_.size(); ++f) {
    FrameState& fs = frames_[f];
    FrameCommand& out = result_.frames[f];
    const ModeSpec& m = s_.states[static_cast<std::size_t>(state_)].modes[f];
    out.mode = m.mode;
    out.spec = &m;
    out.goal = fs.goal;
    out.blending = fs.blending;
    out.setpoint = fs.setpoint;  // at a switch: the blend / trajectory at t = 0 equals it
    fs.prev_target = obs.frames[f].target;
  }
  for (std::size_t i = 0; i < inside_prev_.size(); ++i) inside_prev_[i] = inside_now_[i];
  prev_time_ = obs.time;
  started_ = true;
  return result_;
}

}  // namespace mannequin::scenario
