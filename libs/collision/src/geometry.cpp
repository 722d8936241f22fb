#include "mannequin/collision/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mannequin::collision {

double closestSegmentSegment(const Vector3& p0, const Vector3& p1, const Vector3& q0,
                             const Vector3& q1, double& s, double& t, Vector3& cp, Vector3& cq) {
  // Ericson 5.1.9, with the degenerate cases
  const Vector3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double kEps = 1e-18;
  if (a <= kEps && e <= kEps) {
    s = t = 0.0;
  } else if (a <= kEps) {
    s = 0.0;
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kEps) {
      t = 0.0;
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  cp = p0 + s * d1;
  cq = q0 + t * d2;
  return (cp - cq).norm();
}

Vector3 closestPointTriangle(const Vector3& p, const Vector3& a, const Vector3& b, const Vector3& c) {
  const Vector3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vector3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Vector3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

double closestSegmentTriangle(const Vector3& p0, const Vector3& p1, const Vector3& a,
                              const Vector3& b, const Vector3& c, Vector3& cs, Vector3& ct) {
  // crossing: the segment meets the triangle's plane inside the triangle
  const Vector3 n = (b - a).cross(c - a);
  const double h0 = n.dot(p0 - a), h1 = n.dot(p1 - a);
  if ((h0 <= 0.0 && h1 >= 0.0) || (h0 >= 0.0 && h1 <= 0.0)) {
    if (h0 != h1) {
      const double u = h0 / (h0 - h1);
      const Vector3 x = p0 + u * (p1 - p0);
      // inside test by barycentric signs
      const Vector3 e0 = (b - a).cross(x - a), e1 = (c - b).cross(x - b), e2 = (a - c).cross(x - c);
      if (e0.dot(n) >= 0.0 && e1.dot(n) >= 0.0 && e2.dot(n) >= 0.0) {
        cs = ct = x;
        return 0.0;
      }
    }
  }
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](const Vector3& xs, const Vector3& xt) {
    const double d = (xs - xt).norm();
    if (d < best) {
      best = d;
      cs = xs;
      ct = xt;
    }
  };
  consider(p0, closestPointTriangle(p0, a, b, c));
  consider(p1, closestPointTriangle(p1, a, b, c));
  const Vector3* v[3] = {&a, &b, &c};
  for (int k = 0; k < 3; ++k) {
    double s, t;
    Vector3 xs, xt;
    closestSegmentSegment(p0, p1, *v[k], *v[(k + 1) % 3], s, t, xs, xt);
    consider(xs, xt);
  }
  return best;
}

double signedDistanceBox(const Vector3& p, const Vector3& half, Vector3& surface, Vector3& normal) {
  const Vector3 q = p.cwiseAbs() - half;
  if (q.maxCoeff() > 0.0) {  // outside
    const Vector3 clamped = p.cwiseMax(-half).cwiseMin(half);
    const Vector3 diff = p - clamped;
    const double d = diff.norm();
    surface = clamped;
    normal = diff / d;
    return d;
  }
  // inside: nearest face
  int axis = 0;
  q.maxCoeff(&axis);
  const double sign = p[axis] >= 0.0 ? 1.0 : -1.0;
  surface = p;
  surface[axis] = sign * half[axis];
  normal = Vector3::Zero();
  normal[axis] = sign;
  return q[axis];
}

double closestSegmentBox(const Vector3& p0, const Vector3& p1, const Vector3& half, Vector3& s,
                         Vector3& surface, Vector3& normal) {
  Vector3 sf, nm;
  auto f = [&](double u) { return signedDistanceBox(p0 + u * (p1 - p0), half, sf, nm); };
  double lo = 0.0, hi = 1.0;
  if ((p1 - p0).squaredNorm() > 0.0) {
    constexpr double kPhi = 0.6180339887498949;
    double x1 = hi - kPhi * (hi - lo), x2 = lo + kPhi * (hi - lo);
    double f1 = f(x1), f2 = f(x2);
    const double tol = 1e-12;
    while (hi - lo > tol) {
      if (f1 <= f2) {  // ties go left: deterministic
        hi = x2;
        x2 = x1;
        f2 = f1;
        x1 = hi - kPhi * (hi - lo);
        f1 = f(x1);
      } else {
        lo = x1;
        x1 = x2;
        f1 = f2;
        x2 = lo + kPhi * (hi - lo);
        f2 = f(x2);
      }
    }
  }
  // compare the bracket's middle with both ends (the minimum of a convex function on [0,1])
  double best_u = 0.5 * (lo + hi);
  double best = f(best_u);
  for (double u : {0.0, 1.0}) {
    const double v = f(u);
    if (v < best - 1e-15) {
      best = v;
      best_u = u;
    }
  }
  s = p0 + best_u * (p1 - p0);
  return signedDistanceBox(s, half, surface, normal);
}

Vector3 anyOrthogonal(const Vector3& n) {
  const Vector3 other = std::abs(n.x()) < 0.9 ? Vector3::UnitX() : Vector3::UnitY();
  return n.cross(other).normalized();
}

}  // namespace mannequin::collision
