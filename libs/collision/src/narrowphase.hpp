#pragma once
// Internal: the narrow phase of CollisionWorld (closest points and contact manifolds of one pair).
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/detail/gjk_solver_libccd.h>

#include <memory>
#include <vector>

#include "mannequin/collision/shape.hpp"
#include "mannequin/math/se3.hpp"

namespace mannequin::collision::detail {

using math::SE3;

/// What the narrow phase needs of a collider: its shape, world pose and FCL geometry.
struct ShapeView {
  const Shape* shape = nullptr;
  SE3 oMs;  ///< shape frame in the world
  const fcl::CollisionGeometryd* geometry = nullptr;           ///< FCL primitive (GJK pairs)
  const fcl::BVHModel<fcl::OBBRSSd>* bvh = nullptr;             ///< meshes
};

/// A contact point of a pair (x, y) before margins, world frame: px on x's surface, py on y's,
/// n unit from x to y, d the geometric signed distance along n.
struct RawPoint {
  Vector3 px, py, n;
  double d = 0.0;
  int feature = -1;
};

struct NarrowSettings {
  double cos_face = 0.966;  ///< cos of the face angle
  int max_points = 4;
};

/// Scratch buffers reused between queries.
struct NarrowScratch {
  std::vector<RawPoint> points;
  std::vector<int> stack;
  std::vector<RawPoint> reduced;
  std::vector<char> used;
  int triangles_tested = 0;
  int unsupported_pairs = 0;
  fcl::detail::GJKSolver_libccd<double> gjk;
};

/// Appends to `out` the contact points of pair (x, y) whose distance is ≤ cutoff, with
/// type(x) ≤ type(y) in ShapeType order. Points are in x→y orientation, at most max_points.
void narrowPhase(const ShapeView& x, const ShapeView& y, double cutoff, const NarrowSettings& settings,
                 NarrowScratch& scratch, std::vector<RawPoint>& out);

}  // namespace mannequin::collision::detail
