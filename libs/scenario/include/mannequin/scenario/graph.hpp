#pragma once
/// \file graph.hpp
/// \brief A scenario's state machine as Graphviz DOT text (`mannequin-scenario --graph`): states with
/// each frame's mode and their entry/exit actions, transitions labelled with their events; urgent ones
/// dashed red, resume dotted back to a "resume" node, interrupts from an "any state" node.
#include <string>

#include "mannequin/scenario/scenario.hpp"

namespace mannequin::scenario {

std::string toDot(const Scenario& scenario);

}  // namespace mannequin::scenario
