#pragma once
// Shared helpers of the control tests: the male_50th mannequin and small configs.
#include <cstdlib>
#include <string>

#include "mannequin/control/controller.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

#include "../common/mannequins.hpp"

namespace mannequin::control::testing {

using mannequin::testing::male50;
using mannequin::testing::sourceDir;

inline Vector6 gains(double rot, double lin) {
  Vector6 g;
  g << rot, rot, rot, lin, lin, lin;
  return g;
}

/// A control frame with stiffness (rot, lin) and damping chosen so that k·dt/B = 0.1.
inline ControlFrameConfig frameConfig(const std::string& name, int priority, double k_rot, double k_lin,
                                      double dt = 1e-3) {
  ControlFrameConfig c;
  c.name = name;
  c.frame = name;
  c.priority = priority;
  c.stiffness = gains(k_rot, k_lin);
  c.damping = gains(10 * k_rot * dt, 10 * k_lin * dt);
  return c;
}

/// No gravity, internal control on, no frames.
inline ControllerConfig baseConfig() {
  ControllerConfig c;
  c.gravity.setZero();
  c.internal.stiffness = 150;
  return c;
}

inline math::Matrix3 rotation(const Vector3& axis_angle) { return math::expSO3(axis_angle); }

}  // namespace mannequin::control::testing
