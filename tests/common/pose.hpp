#pragma once
// A pose from a position and a rotation vector (world frame), for tests that script bodies and targets.
#include "mannequin/math/se3.hpp"
#include "mannequin/math/so3.hpp"

namespace mannequin::testing {

/// H = (exp([r]), p): rotation vector r (rad), position p (m).
inline math::SE3 pose(const math::Vector3& p, const math::Vector3& r = math::Vector3::Zero()) {
  return math::SE3(math::expSO3(r), p);
}

}  // namespace mannequin::testing
