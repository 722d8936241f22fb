#pragma once
// The step and gravity the object tests (objects_test, object_guides_test) simulate with.
#include "mannequin/math/types.hpp"

namespace mannequin::testing {

inline const math::Vector3 kGravity(0, 0, -9.81);  ///< m/s², world
inline constexpr double kDt = 0.001;               ///< s

}  // namespace mannequin::testing
