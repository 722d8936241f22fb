#pragma once
/// \file contact.hpp
/// \brief The answer of a collision query: contacts between pairs of bodies in range.
///
/// Conventions (docs/collision.md):
/// - a pair is (a, b) with body_a < body_b (body ids of the CollisionWorld, names from CollisionWorld::bodyName);
/// - `normal` is a unit vector in the WORLD frame pointing from a to b;
/// - `point_a` / `point_b` are the witness points, each in ITS BODY's local frame (scene body
///   frame, or the joint frame of a mannequin segment = skeleton::Data::oMi[segment.joint]), so
///   the simulator can re-evaluate them at the current configuration;
/// - the witness points lie on the margin shells: point_a on body a's surface moved by margin_a
///   along +normal, point_b on b's surface moved by margin_b along −normal, so that
///   distance == normal·(oMb·point_b − oMa·point_a) == d_geometry − margin_a − margin_b
///   (thesis Fig. 4.18: d' = d − 2·margin for equal margins). Negative = interpenetration.
#include <cstdint>
#include <vector>

#include "mannequin/math/types.hpp"

namespace mannequin::collision {

using math::Vector3;

struct Contact {
  int body_a = -1;    ///< smaller body id
  int body_b = -1;    ///< larger body id
  int shape_a = 0;    ///< shape index within body a
  int shape_b = 0;    ///< shape index within body b
  int feature = -1;   ///< triangle index of the mesh of the pair (in its file order), −1 otherwise
  double distance = 0.0;            ///< signed distance after margins (m)
  Vector3 point_a = Vector3::Zero(); ///< witness point on a, body a frame (m)
  Vector3 point_b = Vector3::Zero(); ///< witness point on b, body b frame (m)
  Vector3 normal = Vector3::UnitZ(); ///< unit normal, world frame, from a to b
};

/// Counters of one query (for logs and benchmarks).
struct QueryStats {
  int broadphase_pairs = 0;  ///< pairs whose inflated AABBs overlap (after filters)
  int pairs_in_range = 0;    ///< pairs with at least one contact
  int triangles_tested = 0;  ///< mesh triangles reached by the BVH traversal
  int failed_pairs = 0;      ///< pairs whose narrow phase failed (FCL threw, e.g. on two coincident
                             ///< boxes): no contact is reported for them this query
};

/// A preallocated set of contacts; CollisionWorld::query clears and refills it (keeping its capacity).
struct ContactSet {
  std::uint64_t step = 0;        ///< the simulation step the query was for
  std::vector<Contact> contacts; ///< sorted by (body_a, body_b, shape_a, shape_b, feature, point order)
  QueryStats stats;
};

}  // namespace mannequin::collision
