#include "mannequin/scenario/graph.hpp"

#include <sstream>

#include "mannequin/control/virtual_mechanism.hpp"

namespace mannequin::scenario {

namespace {

// a DOT string literal's content
std::string esc(const std::string& s) {
  std::string out;
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

std::string modeText(const ModeSpec& m, const Scenario& s) {
  switch (m.mode) {
    case ControlMode::kFree: return "free";
    case ControlMode::kConstrained: return std::string("constrained (") + control::toString(m.mechanism->spec.type) + ")";
    case ControlMode::kAutonomous:
      return "autonomous → " + (m.relative_to >= 0 ? s.objects[static_cast<std::size_t>(m.relative_to)].name : std::string("goal"));
  }
  return "?";
}

// the transition's name, and its event when the name is not the event's own description
std::string edgeText(const Transition& t, const Scenario& s) {
  const std::string event = t.when.describe(s.frames, s.objects);
  return t.label == event ? esc(event) : esc(t.label) + "\\n" + esc(event);
}

std::string actionText(const Action& a, const Scenario& s) {
  std::string t = toString(a.kind);
  if (a.frame >= 0) t += " " + s.frames[static_cast<std::size_t>(a.frame)].frame;
  if (a.object >= 0) t += " " + s.objects[static_cast<std::size_t>(a.object)].name;
  return t;
}

}  // namespace

std::string toDot(const Scenario& s) {
  std::vector<bool> unreachable(s.states.size(), false);
  for (const auto& w : s.warnings)
    for (std::size_t i = 0; i < s.states.size(); ++i)
      if (w.where == s.states[i].where) unreachable[i] = true;
  std::ostringstream o;
  o << "digraph \"" << esc(s.name) << "\" {\n"
    << "  label=\"scenario " << esc(s.name) << "\"; labelloc=t; fontname=\"Helvetica\";\n"
    << "  node [shape=box, style=\"rounded,filled\", fillcolor=\"#eef3fb\", fontname=\"Helvetica\", fontsize=10];\n"
    << "  edge [fontname=\"Helvetica\", fontsize=9];\n"
    << "  __start [shape=point, width=0.15, fillcolor=black, label=\"\"];\n";
  bool resume = false;
  for (std::size_t i = 0; i < s.states.size(); ++i) {
    const State& st = s.states[i];
    std::string label = esc(st.name) + "\\n";
    for (std::size_t f = 0; f < s.frames.size(); ++f) label += esc(s.frames[f].frame + ": " + modeText(st.modes[f], s)) + "\\l";
    for (const auto& a : st.entry) label += "entry: " + esc(actionText(a, s)) + "\\l";
    for (const auto& a : st.exit) label += "exit: " + esc(actionText(a, s)) + "\\l";
    o << "  s" << i << " [label=\"" << label << "\"";
    if (unreachable[i]) o << ", fillcolor=\"#dddddd\", fontcolor=\"#777777\", xlabel=\"unreachable\"";
    o << "];\n";
    for (const auto& t : st.transitions) resume = resume || t.resume;
  }
  o << "  __start -> s" << s.initial << ";\n";
  if (resume) o << "  __resume [shape=plaintext, style=\"\", label=\"resume\\n(interrupted state)\"];\n";
  if (!s.interrupts.empty()) o << "  __any [shape=plaintext, style=\"\", label=\"any state\"];\n";
  for (std::size_t i = 0; i < s.states.size(); ++i) {
    for (const auto& t : s.states[i].transitions) {
      o << "  s" << i << " -> ";
      if (t.resume) {
        o << "__resume [style=dotted, label=\"" << edgeText(t, s) << "\"];\n";
      } else {
        o << "s" << t.to << " [label=\"" << (t.urgent ? "urgent: " : "") << edgeText(t, s) << "\"";
        if (t.urgent) o << ", style=dashed, color=\"#c0392b\", fontcolor=\"#c0392b\"";
        o << "];\n";
      }
    }
  }
  for (const auto& t : s.interrupts)
    o << "  __any -> s" << t.to << " [label=\"urgent: " << edgeText(t, s)
      << "\", style=dashed, color=\"#c0392b\", fontcolor=\"#c0392b\"];\n";
  o << "}\n";
  return o.str();
}

}  // namespace mannequin::scenario
