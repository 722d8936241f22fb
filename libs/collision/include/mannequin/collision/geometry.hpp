#pragma once
/// \file geometry.hpp
/// \brief Closed-form closest points between primitives (all points and vectors in one common
/// frame, the caller's). Used by the narrow phase and checked against hand-computed cases.
#include "mannequin/math/types.hpp"

namespace mannequin::collision {

using math::Vector3;

/// Closest points of segments [p0,p1] and [q0,q1]: parameters s, t ∈ [0,1] and points
/// cp = p0 + s(p1−p0), cq = q0 + t(q1−q0). Returns the distance. Degenerate segments allowed.
double closestSegmentSegment(const Vector3& p0, const Vector3& p1, const Vector3& q0,
                             const Vector3& q1, double& s, double& t, Vector3& cp, Vector3& cq);

/// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5).
Vector3 closestPointTriangle(const Vector3& p, const Vector3& a, const Vector3& b, const Vector3& c);

/// Closest points of segment [p0,p1] and triangle (a,b,c); returns the (unsigned) distance,
/// 0 when the segment crosses the triangle (then cs == ct is the crossing point).
double closestSegmentTriangle(const Vector3& p0, const Vector3& p1, const Vector3& a,
                              const Vector3& b, const Vector3& c, Vector3& cs, Vector3& ct);

/// Signed distance from p to the box [−half, half] (negative inside); `surface` is the closest
/// point of the box surface and `normal` the outward unit normal there (gradient of the
/// distance; for a point inside, the normal of the nearest face).
double signedDistanceBox(const Vector3& p, const Vector3& half, Vector3& surface, Vector3& normal);

/// Minimum over the segment [p0,p1] of signedDistanceBox (convex in the parameter: golden-section
/// search to 1e-12 of the length). Returns the distance; `s` the segment point, `surface`/`normal`
/// as signedDistanceBox at that point.
double closestSegmentBox(const Vector3& p0, const Vector3& p1, const Vector3& half, Vector3& s,
                         Vector3& surface, Vector3& normal);

/// Unit vector orthogonal to n (deterministic choice).
Vector3 anyOrthogonal(const Vector3& n);

}  // namespace mannequin::collision
