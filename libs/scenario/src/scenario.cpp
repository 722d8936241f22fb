#include "mannequin/scenario/scenario.hpp"

#include <cmath>
#include <set>
#include <sstream>

namespace mannequin::scenario {

using core::ConfigNode;

const char* toString(ControlMode mode) {
  switch (mode) {
    case ControlMode::kFree: return "free";
    case ControlMode::kConstrained: return "constrained";
    case ControlMode::kAutonomous: return "autonomous";
  }
  return "?";
}

const char* toString(Action::Kind kind) {
  switch (kind) {
    case Action::Kind::kGrasp: return "grasp";
    case Action::Kind::kRelease: return "release";
    case Action::Kind::kAttachGuide: return "attach_guide";
    case Action::Kind::kDetachGuide: return "detach_guide";
    case Action::Kind::kSetGains: return "set_gains";
  }
  return "?";
}

bool Zone::contains(const Vector3& x) const {
  const Vector3 local = pose.actInv(x);
  if (sphere) return local.squaredNorm() <= radius * radius;
  return (local.cwiseAbs() - half_extents).maxCoeff() <= 0.0;
}

int Scenario::stateIndex(const std::string& n) const {
  for (std::size_t i = 0; i < states.size(); ++i)
    if (states[i].name == n) return static_cast<int>(i);
  return -1;
}

int Scenario::frameIndex(const std::string& n) const {
  int found = -1;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].name() == n) return static_cast<int>(i);
    if (frames[i].frame == n) {
      if (found >= 0) return -1;  // ambiguous bare name
      found = static_cast<int>(i);
    }
  }
  return found;
}

int Scenario::objectIndex(const std::string& n) const {
  for (std::size_t i = 0; i < objects.size(); ++i)
    if (objects[i].name == n) return static_cast<int>(i);
  return -1;
}

int Scenario::triggerIndex(const std::string& n) const {
  for (std::size_t i = 0; i < triggers.size(); ++i)
    if (triggers[i] == n) return static_cast<int>(i);
  return -1;
}

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "none declared" : s;
}

std::string fmt(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

SE3 pose(const ConfigNode& n) {
  n.allowOnly({"xyz", "rpy_deg"});
  SE3 H;
  if (const auto p = n.find("xyz")) H.p = p->vec3();
  if (const auto r = n.find("rpy_deg")) H.R = r->rpyDeg();
  return H;
}

// 6 numbers (rotation xyz, translation xyz) or {rotation: r, translation: t}, all >= 0
Vector6 gains(const ConfigNode& n) {
  Vector6 g;
  if (n.isMap()) {
    n.allowOnly({"rotation", "translation"});
    const auto r = n.find("rotation"), t = n.find("translation");
    const double rv = r ? r->nonNegative() : 0.0, tv = t ? t->nonNegative() : 0.0;
    g << rv, rv, rv, tv, tv, tv;
    return g;
  }
  const auto items = n.items();
  if (items.size() != 6) n.fail("expected 6 numbers (rotation xyz, translation xyz) or {rotation: r, translation: t}");
  for (int i = 0; i < 6; ++i) g(i) = items[i].nonNegative();
  return g;
}

class Reader {
 public:
  explicit Reader(Scenario& s) : s_(s) {}

  void read(const ConfigNode& root) {
    root.allowOnly({"scenario", "mannequins", "objects", "triggers", "initial", "interrupts", "states"});
    s_.source = root.file();
    s_.name = root["scenario"].str();
    readMannequins(root["mannequins"]);
    if (const auto o = root.find("objects")) readObjects(*o);
    if (const auto t = root.find("triggers")) {
      for (const ConfigNode& n : t->items()) {
        const std::string name = n.str();
        if (s_.triggerIndex(name) >= 0) n.fail("duplicate trigger '" + name + "'");
        s_.triggers.push_back(name);
      }
    }
    // states: names first (transitions may point forward)
    const ConfigNode states = root["states"];
    const std::vector<ConfigNode> items = states.items();
    if (items.empty()) states.fail("a scenario needs at least one state");
    for (const ConfigNode& n : items) {
      if (!n.isMap()) n.fail("expected a state {name, modes, entry, exit, transitions}");
      const ConfigNode name = n["name"];
      State st;
      st.name = name.str();
      st.where = n.where();
      if (st.name.empty()) name.fail("empty state name");
      if (st.name == "resume") name.fail("'resume' is reserved (a transition's resume: true)");
      if (s_.stateIndex(st.name) >= 0)
        name.fail("duplicate state '" + st.name + "' (first at " + s_.states[s_.stateIndex(st.name)].where + ")");
      s_.states.push_back(std::move(st));
    }
    for (std::size_t i = 0; i < items.size(); ++i) readState(items[i], s_.states[i]);
    if (const auto n = root.find("initial")) {
      s_.initial = stateRef(*n);
    } else {
      s_.initial = 0;
    }
    if (const auto list = root.find("interrupts")) {
      for (const ConfigNode& n : list->items()) {
        Transition t = transition(n, nullptr);
        if (t.resume) n["resume"].fail("an interrupt goes to a state; resume belongs to the interrupting states");
        t.urgent = true;
        s_.interrupts.push_back(std::move(t));
      }
    }
    checkResume();
    warnUnreachable();
  }

 private:
  Scenario& s_;

  void readMannequins(const ConfigNode& list) {
    for (const ConfigNode& m : list.items()) {
      m.allowOnly({"name", "frames"});
      const std::string name = m["name"].str();
      for (const auto& other : s_.mannequins)
        if (other == name) m["name"].fail("duplicate mannequin '" + name + "'");
      s_.mannequins.push_back(name);
      const ConfigNode frames = m["frames"];
      for (const ConfigNode& f : frames.items()) {
        FrameRef ref{name, f.str()};
        for (const auto& other : s_.frames)
          if (other.name() == ref.name()) f.fail("duplicate control frame '" + ref.frame + "'");
        s_.frames.push_back(ref);
      }
    }
    if (s_.frames.empty()) list.fail("a scenario commands at least one control frame (mannequins[].frames)");
  }

  void readObjects(const ConfigNode& list) {
    for (const ConfigNode& n : list.items()) {
      ObjectDecl o;
      if (n.isScalar()) {
        o.name = n.str();
      } else {
        n.allowOnly({"name", "values"});
        o.name = n["name"].str();
        if (const auto v = n.find("values")) o.values = v->strings();
      }
      if (s_.objectIndex(o.name) >= 0) n.fail("duplicate object '" + o.name + "'");
      s_.objects.push_back(std::move(o));
    }
  }

  std::vector<std::string> frameNames() const {
    std::vector<std::string> v;
    for (const auto& f : s_.frames) v.push_back(f.name());
    return v;
  }
  std::vector<std::string> stateNames() const {
    std::vector<std::string> v;
    for (const auto& st : s_.states) v.push_back(st.name);
    return v;
  }
  std::vector<std::string> objectNames() const {
    std::vector<std::string> v;
    for (const auto& o : s_.objects) v.push_back(o.name);
    return v;
  }

  int frameRef(const ConfigNode& n) const {
    const std::string name = n.str();
    const int i = s_.frameIndex(name);
    if (i < 0) {
      int bare = 0;
      for (const auto& f : s_.frames) bare += f.frame == name;
      if (bare > 1) n.fail("control frame '" + name + "' is ambiguous: write mannequin.frame");
      n.fail("unknown control frame '" + name + "' (frames: " + join(frameNames()) + ")");
    }
    return i;
  }
  int objectRef(const ConfigNode& n) const {
    const std::string name = n.str();
    const int i = s_.objectIndex(name);
    if (i < 0) n.fail("unknown object '" + name + "' (objects: " + join(objectNames()) + ")");
    return i;
  }
  int stateRef(const ConfigNode& n) const {
    const std::string name = n.str();
    const int i = s_.stateIndex(name);
    if (i < 0) n.fail("unknown state '" + name + "' (states: " + join(stateNames()) + ")");
    return i;
  }

  ModeSpec mode(const ConfigNode& n) const {
    ModeSpec m;
    m.where = n.where();
    static const std::vector<std::string> kModes = {"free", "constrained", "autonomous"};
    if (n.isScalar()) {
      m.mode = static_cast<ControlMode>(n.choice(kModes));
      if (m.mode != ControlMode::kFree)
        n.fail(std::string(toString(m.mode)) + " needs a map {mode: " + toString(m.mode) + ", ...}");
      return m;
    }
    if (!n.has("mode")) n.fail("missing key 'mode' (free, constrained, autonomous)");
    m.mode = static_cast<ControlMode>(n["mode"].choice(kModes));
    if (const auto b = n.find("blend_s")) m.blend = b->positive();
    switch (m.mode) {
      case ControlMode::kFree:
        n.allowOnly({"mode", "blend_s"});
        break;
      case ControlMode::kConstrained:
        n.allowOnly({"mode", "blend_s", "mechanism"});
        if (!n.has("mechanism")) n.fail("a constrained mode needs a 'mechanism' (type, origin, limits, force)");
        m.mechanism = control::parseMechanismConfig(n["mechanism"]);
        break;
      case ControlMode::kAutonomous: {
        n.allowOnly({"mode", "blend_s", "goal", "relative_to", "duration_s", "profile"});
        if (!n.has("goal")) n.fail("an autonomous mode needs a 'goal' {xyz, rpy_deg}");
        m.goal = pose(n["goal"]);
        if (const auto r = n.find("relative_to")) m.relative_to = objectRef(*r);
        if (!n.has("duration_s")) n.fail("an autonomous mode needs 'duration_s' (s)");
        m.duration = n["duration_s"].positive();
        if (const auto p = n.find("profile")) p->choice({"minimum_jerk"});
        break;
      }
    }
    return m;
  }

  Action action(const ConfigNode& n) const {
    if (!n.isMap() || n.keys().size() != 1)
      n.fail("an action is a map with one key: grasp, release, attach_guide, detach_guide or set_gains");
    const std::string key = n.keys()[0];
    const ConfigNode a = n[key];
    Action act;
    act.where = n.where();
    static const std::vector<std::string> kKinds = {"grasp", "release", "attach_guide", "detach_guide", "set_gains"};
    bool known = false;
    for (std::size_t i = 0; i < kKinds.size(); ++i)
      if (kKinds[i] == key) {
        act.kind = static_cast<Action::Kind>(i);
        known = true;
      }
    if (!known) n.fail("unknown action '" + key + "' (expected grasp, release, attach_guide, detach_guide or set_gains)");
    switch (act.kind) {
      case Action::Kind::kGrasp:
        a.allowOnly({"frame", "object"});
        act.frame = frameRef(a["frame"]);
        act.object = objectRef(a["object"]);
        break;
      case Action::Kind::kRelease:
        a.allowOnly({"frame", "object"});
        act.frame = frameRef(a["frame"]);
        if (const auto o = a.find("object")) act.object = objectRef(*o);
        break;
      case Action::Kind::kAttachGuide:
        a.allowOnly({"object", "mechanism"});
        act.object = objectRef(a["object"]);
        act.mechanism = control::parseMechanismConfig(a["mechanism"]);
        break;
      case Action::Kind::kDetachGuide:
        a.allowOnly({"object"});
        act.object = objectRef(a["object"]);
        break;
      case Action::Kind::kSetGains:
        a.allowOnly({"frame", "stiffness", "damping"});
        act.frame = frameRef(a["frame"]);
        if (const auto k = a.find("stiffness")) act.stiffness = gains(*k);
        if (const auto b = a.find("damping")) act.damping = gains(*b);
        if (!act.stiffness && !act.damping) a.fail("set_gains needs 'stiffness' or 'damping'");
        break;
    }
    return act;
  }

  Zone zone(const ConfigNode& n) const {
    Zone z;
    const bool s = n.has("sphere"), b = n.has("box");
    if (s == b) n.fail("a zone is either 'sphere: {center, radius}' or 'box: {center, half_extents, rpy_deg}'");
    if (s) {
      const ConfigNode sp = n["sphere"];
      sp.allowOnly({"center", "radius"});
      z.sphere = true;
      z.pose.p = sp["center"].vec3();
      z.radius = sp["radius"].positive();
    } else {
      const ConfigNode bx = n["box"];
      bx.allowOnly({"center", "half_extents", "rpy_deg"});
      z.sphere = false;
      z.pose.p = bx["center"].vec3();
      if (const auto r = bx.find("rpy_deg")) z.pose.R = r->rpyDeg();
      z.half_extents = bx["half_extents"].vec3();
      if (z.half_extents.minCoeff() <= 0) bx["half_extents"].fail("half extents must be > 0");
    }
    return z;
  }

  // above: X or below: X (exactly one)
  void compare(const ConfigNode& n, Condition& c, bool non_negative) const {
    const bool a = n.has("above"), b = n.has("below");
    if (a == b) n.fail("give exactly one of 'above' or 'below'");
    const ConfigNode v = a ? n["above"] : n["below"];
    c.above = a;
    c.threshold = non_negative ? v.nonNegative() : v.num();
  }

  // `state` is the state whose transition this is (nullptr for interrupts): kReached's default goal
  Condition condition(const ConfigNode& n, const State* state) {
    Condition c;
    c.where = n.where();
    if (!n.isMap() || n.keys().size() != 1)
      n.fail("an event is a map with one key (inside, outside, enter, leave, distance, force, reached, time, "
             "object, trigger, all, any, not)");
    const std::string key = n.keys()[0];
    const ConfigNode v = n[key];
    using K = Condition::Kind;
    if (key == "inside" || key == "outside" || key == "enter" || key == "leave") {
      c.kind = key == "inside" ? K::kInside : key == "outside" ? K::kOutside : key == "enter" ? K::kEnter : K::kLeave;
      v.allowOnly({"frame", "sphere", "box"});
      c.frame = frameRef(v["frame"]);
      c.zone = zone(v);
      if (c.kind == K::kEnter || c.kind == K::kLeave) c.memory = s_.memory_slots++;
    } else if (key == "distance") {
      c.kind = K::kDistance;
      v.allowOnly({"frame", "to_frame", "object", "point", "above", "below"});
      c.frame = frameRef(v["frame"]);
      const int targets = v.has("to_frame") + v.has("object") + v.has("point");
      if (targets != 1) v.fail("give exactly one of 'to_frame', 'object' or 'point'");
      if (const auto f = v.find("to_frame")) c.other_frame = frameRef(*f);
      if (const auto o = v.find("object")) c.object = objectRef(*o);
      if (const auto p = v.find("point")) c.point = p->vec3();
      compare(v, c, true);
    } else if (key == "force") {
      c.kind = K::kForce;
      v.allowOnly({"frame", "above", "below"});
      c.frame = frameRef(v["frame"]);
      compare(v, c, true);
    } else if (key == "reached") {
      c.kind = K::kReached;
      v.allowOnly({"frame", "pose", "relative_to", "tolerance_m", "tolerance_deg"});
      c.frame = frameRef(v["frame"]);
      if (const auto p = v.find("pose")) c.pose = pose(*p);
      if (const auto r = v.find("relative_to")) {
        if (!c.pose) r->fail("relative_to needs a 'pose'");
        c.object = objectRef(*r);
      }
      if (const auto t = v.find("tolerance_m")) c.tolerance_m = t->positive();
      if (const auto t = v.find("tolerance_deg")) c.tolerance_rad = t->numIn(1e-9, 180.0) * M_PI / 180.0;
      if (!c.pose) {
        if (state == nullptr)
          v.fail("'reached' without a 'pose' means the frame's autonomous goal: give a pose in an interrupt");
        if (state->modes[static_cast<std::size_t>(c.frame)].mode != ControlMode::kAutonomous)
          v["frame"].fail("frame '" + s_.frames[static_cast<std::size_t>(c.frame)].name() + "' is not autonomous in state '" +
                          state->name + "': give the 'pose' to reach");
      }
    } else if (key == "time") {
      c.kind = K::kTime;
      c.threshold = v.nonNegative();
    } else if (key == "object") {
      c.kind = K::kObject;
      v.allowOnly({"name", "value", "above", "below"});
      c.object = objectRef(v["name"]);
      const ConfigNode value = v["value"];
      const auto& values = s_.objects[static_cast<std::size_t>(c.object)].values;
      for (std::size_t i = 0; i < values.size(); ++i)
        if (values[i] == value.str()) c.value_index = static_cast<int>(i);
      if (c.value_index < 0)
        value.fail("object '" + s_.objects[static_cast<std::size_t>(c.object)].name + "' has no value '" + value.str() +
                   "' (values: " + join(values) + ")");
      compare(v, c, false);
    } else if (key == "trigger") {
      c.kind = K::kTrigger;
      // (no ConfigNode assignment: a YAML::Node's operator= writes into the node it refers to)
      if (v.isMap()) {
        v.allowOnly({"name", "value"});
        c.trigger_value = v.get("value", std::string());
      }
      const ConfigNode name = v.isMap() ? v["name"] : v;
      c.trigger = name.str();
      if (s_.triggerIndex(c.trigger) < 0)
        name.fail("unknown trigger '" + c.trigger + "' (triggers: " + join(s_.triggers) + ")");
    } else if (key == "all" || key == "any") {
      c.kind = key == "all" ? K::kAll : K::kAny;
      const auto items = v.items();
      if (items.empty()) v.fail("'" + key + "' needs at least one event");
      for (const ConfigNode& i : items) c.children.push_back(condition(i, state));
    } else if (key == "not") {
      c.kind = K::kNot;
      c.children.push_back(condition(v, state));
    } else {
      n.fail("unknown event '" + key + "' (expected inside, outside, enter, leave, distance, force, reached, time, "
             "object, trigger, all, any, not)");
    }
    return c;
  }

  Transition transition(const ConfigNode& n, const State* state) {
    n.allowOnly({"to", "resume", "urgent", "name", "when"});
    Transition t;
    t.where = n.where();
    const bool resume = n.get("resume", false);
    if (n.has("to") == resume)
      n.fail("a transition goes somewhere: give 'to: STATE' or 'resume: true' (not both)");
    t.resume = resume;
    if (!resume) t.to = stateRef(n["to"]);
    t.urgent = n.get("urgent", false);
    if (t.urgent && t.resume) n["urgent"].fail("a resume transition cannot be urgent");
    if (!n.has("when")) n.fail("a transition needs 'when' (the event that fires it)");
    t.when = condition(n["when"], state);
    t.label = n.has("name") ? n["name"].str() : t.when.describe(s_.frames, s_.objects);
    return t;
  }

  void readState(const ConfigNode& n, State& st) {
    n.allowOnly({"name", "modes", "entry", "exit", "transitions"});
    st.modes.assign(s_.frames.size(), ModeSpec{});
    for (auto& m : st.modes) m.where = st.where;
    if (const auto modes = n.find("modes")) {
      for (const std::string& key : modes->keys()) {
        const int f = s_.frameIndex(key);
        const ConfigNode m = (*modes)[key];
        if (f < 0) {
          // name the key's line: the value node is the closest we have
          m.fail("unknown control frame '" + key + "' (frames: " + join(frameNames()) + ")");
        }
        st.modes[static_cast<std::size_t>(f)] = mode(m);
      }
    }
    if (const auto e = n.find("entry"))
      for (const ConfigNode& a : e->items()) st.entry.push_back(action(a));
    if (const auto e = n.find("exit"))
      for (const ConfigNode& a : e->items()) st.exit.push_back(action(a));
    if (const auto ts = n.find("transitions"))
      for (const ConfigNode& t : ts->items()) st.transitions.push_back(transition(t, &st));
  }

  void checkResume() const {
    bool urgent = !s_.interrupts.empty();
    for (const auto& st : s_.states)
      for (const auto& t : st.transitions) urgent = urgent || t.urgent;
    if (urgent) return;
    for (const auto& st : s_.states)
      for (const auto& t : st.transitions)
        if (t.resume)
          core::failAt(t.where, "resume",
                       "'resume' in state '" + st.name + "' but no urgent transition or interrupt pushes a context");
  }

  void warnUnreachable() {
    std::vector<bool> seen(s_.states.size(), false);
    std::vector<int> todo{s_.initial};
    seen[static_cast<std::size_t>(s_.initial)] = true;
    for (const auto& t : s_.interrupts)
      if (!seen[static_cast<std::size_t>(t.to)]) {
        seen[static_cast<std::size_t>(t.to)] = true;
        todo.push_back(t.to);
      }
    while (!todo.empty()) {
      const int i = todo.back();
      todo.pop_back();
      for (const auto& t : s_.states[static_cast<std::size_t>(i)].transitions)
        if (t.to >= 0 && !seen[static_cast<std::size_t>(t.to)]) {
          seen[static_cast<std::size_t>(t.to)] = true;
          todo.push_back(t.to);
        }
    }
    for (std::size_t i = 0; i < s_.states.size(); ++i)
      if (!seen[i])
        s_.warnings.push_back({s_.states[i].where, "state '" + s_.states[i].name + "' is unreachable from the initial state '" +
                                                      s_.states[static_cast<std::size_t>(s_.initial)].name + "'"});
  }
};

}  // namespace

std::string Condition::describe(const std::vector<FrameRef>& frames, const std::vector<ObjectDecl>& objects) const {
  const auto fr = [&](int i) { return i >= 0 ? frames[static_cast<std::size_t>(i)].frame : std::string("?"); };
  const auto ob = [&](int i) { return i >= 0 ? objects[static_cast<std::size_t>(i)].name : std::string("?"); };
  const std::string cmp = std::string(above ? " > " : " < ") + fmt(threshold);
  const std::string z = zone.sphere ? "sphere" : "box";
  std::string s;
  switch (kind) {
    case Kind::kInside: return fr(frame) + " inside " + z;
    case Kind::kOutside: return fr(frame) + " outside " + z;
    case Kind::kEnter: return fr(frame) + " enters " + z;
    case Kind::kLeave: return fr(frame) + " leaves " + z;
    case Kind::kDistance:
      return "dist(" + fr(frame) + ", " +
             (other_frame >= 0 ? fr(other_frame) : object >= 0 ? ob(object) : std::string("point")) + ")" + cmp;
    case Kind::kForce: return "|F " + fr(frame) + "|" + cmp;
    case Kind::kReached: return fr(frame) + " reached" + (pose ? std::string(" pose") : std::string(" goal"));
    case Kind::kTime: return "t ≥ " + fmt(threshold) + " s";
    case Kind::kObject:
      return ob(object) + "." + objects[static_cast<std::size_t>(object)].values[static_cast<std::size_t>(value_index)] + cmp;
    case Kind::kTrigger: return "trigger " + trigger + (trigger_value.empty() ? "" : "=" + trigger_value);
    case Kind::kAll:
    case Kind::kAny:
      for (const auto& c : children) s += (s.empty() ? "" : kind == Kind::kAll ? " and " : " or ") + c.describe(frames, objects);
      return children.size() > 1 ? "(" + s + ")" : s;
    case Kind::kNot: return "not " + children[0].describe(frames, objects);
  }
  return "?";
}

Scenario parseScenario(const std::string& yaml_text, const std::string& source) {
  Scenario s;
  Reader(s).read(ConfigNode::parse(yaml_text, source));
  return s;
}

Scenario loadScenario(const std::string& path) {
  Scenario s;
  Reader(s).read(ConfigNode::load(path));
  return s;
}

}  // namespace mannequin::scenario
