#pragma once
// The rigid bodies of a VR-room actor as the World tests script them (one per control frame of the set-up),
// and the smallest set-up they use.
#include <utility>
#include <vector>

#include "mannequin/sim/world.hpp"
#include "../common/mannequins.hpp"

namespace mannequin::testing {

inline constexpr const char* kActorBodies[] = {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r"};


/// One mannequin, "operator" (male_50th), with two control frames driven by the bodies of the same names:
/// pelvis and hand_l.
inline std::vector<sim::MannequinSetup> pelvisAndLeftHandOperator() {
  sim::MannequinSetup s;
  s.name = "operator";
  s.model = male50();
  s.frames = {{"pelvis", "pelvis"}, {"hand_l", "hand_l"}};
  return {std::move(s)};
}

}  // namespace mannequin::testing
