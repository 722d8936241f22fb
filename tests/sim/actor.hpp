#pragma once
// The rigid bodies of a VR-room actor as the World tests script them (one per control frame of the set-up).
namespace mannequin::testing {

inline constexpr const char* kActorBodies[] = {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r"};

}  // namespace mannequin::testing
