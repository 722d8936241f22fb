#pragma once
// Shared by the joint-limit tests: the 50th-percentile male, coordinate lookup by name, and a controller
// config with only the posture control (no gravity, no control frame).
#include <gtest/gtest.h>

#include <string>

#include "mannequin/control/config.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

#include "../common/mannequins.hpp"

namespace mannequin::testing_fixture {

using mannequin::testing::male50;

inline int coordinate(const std::string& name) {
  const auto names = male50().coordinateNames();
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return static_cast<int>(k);
  ADD_FAILURE() << "no coordinate " << name;
  return -1;
}

/// No gravity, no control frame: only the posture control (k_int 150 N·m/rad) moves the joints.
inline control::ControllerConfig postureOnly() {
  control::ControllerConfig c;
  c.gravity.setZero();
  c.internal.stiffness = 150;
  c.internal.projection = control::InternalProjection::kNone;
  c.internal.observer.enabled = false;
  return c;
}

}  // namespace mannequin::testing_fixture
