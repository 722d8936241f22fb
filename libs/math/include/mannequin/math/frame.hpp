#pragma once
/// \file frame.hpp
/// \brief A deterministic rotation whose z axis points along a direction (the frame of a capsule or
/// cylinder along a segment): z = dir/|dir|, x = the world z axis (or x when z is within ~25° of it)
/// projected orthogonally to z, y = z × x.
#include <cmath>

#include "mannequin/math/types.hpp"

namespace mannequin::math {

/// \pre dir ≠ 0.
inline Matrix3 frameAlong(const Vector3& dir) {
  const Vector3 z = dir.normalized();
  Vector3 ref = Vector3::UnitZ();
  if (std::abs(z.dot(ref)) > 0.9) ref = Vector3::UnitX();
  const Vector3 x = (ref - ref.dot(z) * z).normalized();
  Matrix3 R;
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  return R;
}

}  // namespace mannequin::math
