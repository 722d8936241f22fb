#include "narrowphase.hpp"

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "mannequin/collision/geometry.hpp"

namespace mannequin::collision::detail {
namespace {

constexpr double kTiny = 1e-12;
constexpr int kMaxPoly = 24;

/// A planar face (reference) or a set of incident points (core points + radius).
struct Feature {
  std::array<Vector3, 8> v;
  int n = 0;
  double radius = 0.0;
  Vector3 normal = Vector3::UnitZ();  ///< face: outward unit normal
  Vector3 point = Vector3::Zero();    ///< face: a point of its plane
  double align = -1.0;                ///< face: normal·direction asked for
  bool infinite = false;              ///< face of a plane
};

Vector3 axisOf(const ShapeView& s) { return s.oMs.R.col(2); }

// core segment of a capsule or sphere (p0 == p1 for a sphere)
void core(const ShapeView& s, Vector3& p0, Vector3& p1) {
  const double h = s.shape->type == ShapeType::kCapsule ? 0.5 * s.shape->length : 0.0;
  p0 = s.oMs.act(Vector3(0, 0, -h));
  p1 = s.oMs.act(Vector3(0, 0, h));
}

void boxFace(const ShapeView& s, const Vector3& u, Feature& f) {
  const Vector3 ul = s.oMs.R.transpose() * u;
  int k = 0;
  ul.cwiseAbs().maxCoeff(&k);
  const double sign = ul[k] >= 0.0 ? 1.0 : -1.0;
  const Vector3 h = 0.5 * s.shape->size;
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  Vector3 c = Vector3::Zero();
  c[k] = sign * h[k];
  const double a[4] = {1, -1, -1, 1}, b[4] = {1, 1, -1, -1};
  for (int q = 0; q < 4; ++q) {
    Vector3 v = c;
    v[i] = a[q] * h[i];
    v[j] = b[q] * h[j];
    f.v[q] = s.oMs.act(v);
  }
  f.n = 4;
  f.radius = 0.0;
  f.normal = sign * s.oMs.R.col(k);
  f.point = s.oMs.act(c);
  f.align = std::abs(ul[k]);
  f.infinite = false;
}

/// The face of `s` whose outward normal is most aligned with u; false if `s` has no flat face.
bool faceOf(const ShapeView& s, const Vector3& u, Feature& f) {
  switch (s.shape->type) {
    case ShapeType::kBox: boxFace(s, u, f); return true;
    case ShapeType::kPlane:
      f.normal = s.oMs.R * s.shape->normal;
      f.point = s.oMs.act(s.shape->offset * s.shape->normal);
      f.align = f.normal.dot(u);
      f.infinite = true;
      f.n = 0;
      return true;
    case ShapeType::kCylinder: {
      const Vector3 al = axisOf(s);
      const double dot = al.dot(u);
      const double sign = dot >= 0.0 ? 1.0 : -1.0;
      f.normal = sign * al;
      f.point = s.oMs.act(Vector3(0, 0, sign * 0.5 * s.shape->length));
      f.align = std::abs(dot);
      f.infinite = false;
      f.n = 8;
      const Vector3 e1 = s.oMs.R.col(0), e2 = s.oMs.R.col(1);
      for (int q = 0; q < 8; ++q) {
        const double t = q * 0.25 * 3.14159265358979323846;
        f.v[q] = f.point + s.shape->radius * (std::cos(t) * e1 + std::sin(t) * e2);
      }
      return true;
    }
    default: return false;
  }
}

/// Points of `s` furthest along u (the support feature), as core points plus a radius.
void incidentOf(const ShapeView& s, const Vector3& u, double cos_face, Feature& f) {
  f.infinite = false;
  switch (s.shape->type) {
    case ShapeType::kBox: boxFace(s, u, f); return;
    case ShapeType::kCapsule:
    case ShapeType::kSphere: {
      core(s, f.v[0], f.v[1]);
      f.n = s.shape->type == ShapeType::kCapsule && s.shape->length > 0.0 ? 2 : 1;
      f.radius = s.shape->radius;
      return;
    }
    case ShapeType::kCylinder: {
      const Vector3 al = axisOf(s);
      const double dot = al.dot(u);
      Vector3 w = u - dot * al;
      w = w.norm() > 1e-9 ? w.normalized() : Vector3(s.oMs.R.col(0));
      const Vector3 c = s.oMs.p;
      const double h = 0.5 * s.shape->length, r = s.shape->radius;
      f.radius = 0.0;
      if (std::abs(dot) >= cos_face) {  // cap rim, starting at the support point
        const double sign = dot >= 0.0 ? 1.0 : -1.0;
        const Vector3 w2 = al.cross(w);
        f.n = 8;
        for (int q = 0; q < 8; ++q) {
          const double t = q * 0.25 * 3.14159265358979323846;
          f.v[q] = c + sign * h * al + r * (std::cos(t) * w + std::sin(t) * w2);
        }
      } else {  // side line
        f.n = 2;
        f.v[0] = c - h * al + r * w;
        f.v[1] = c + h * al + r * w;
      }
      return;
    }
    default: f.n = 0; return;
  }
}

/// Clips the incident points (point, segment or convex polygon) to the prism of the face.
int clipToFace(const Feature& face, const Feature& inc, std::array<Vector3, kMaxPoly>& out) {
  std::array<Vector3, kMaxPoly> tmp;
  int n = inc.n;
  for (int k = 0; k < n; ++k) out[k] = inc.v[k];
  if (face.infinite || n == 0) return n;
  Vector3 centroid = Vector3::Zero();
  for (int k = 0; k < face.n; ++k) centroid += face.v[k];
  centroid /= face.n;
  constexpr double kEps = 1e-12;
  for (int e = 0; e < face.n && n > 0; ++e) {
    const Vector3& a = face.v[e];
    const Vector3& b = face.v[(e + 1) % face.n];
    Vector3 m = face.normal.cross(b - a);
    if (m.dot(centroid - a) < 0.0) m = -m;
    const double mn = m.norm();
    if (mn < kTiny) continue;
    m /= mn;
    auto side = [&](const Vector3& x) { return m.dot(x - a); };
    if (n == 1) {
      if (side(out[0]) < -kEps) n = 0;
    } else if (n == 2) {
      const double s0 = side(out[0]), s1 = side(out[1]);
      if (s0 < -kEps && s1 < -kEps) {
        n = 0;
      } else if (s0 < -kEps) {
        out[0] = out[0] + (s0 / (s0 - s1)) * (out[1] - out[0]);
      } else if (s1 < -kEps) {
        out[1] = out[1] + (s1 / (s1 - s0)) * (out[0] - out[1]);
      }
    } else {  // Sutherland–Hodgman
      int m_out = 0;
      for (int k = 0; k < n; ++k) {
        const Vector3& p = out[k];
        const Vector3& q = out[(k + 1) % n];
        const double sp = side(p), sq = side(q);
        if (sp >= -kEps) {
          if (m_out < kMaxPoly) tmp[m_out++] = p;
          if (sq < -kEps && m_out < kMaxPoly) tmp[m_out++] = p + (sp / (sp - sq)) * (q - p);
        } else if (sq >= -kEps && m_out < kMaxPoly) {
          tmp[m_out++] = p + (sp / (sp - sq)) * (q - p);
        }
      }
      n = m_out;
      for (int k = 0; k < n; ++k) out[k] = tmp[k];
    }
  }
  return n;
}

/// Contact points of the clipped incident feature against the reference face. `flip`: the face
/// belongs to y (points are then turned to x→y).
int facePoints(const Feature& face, const Feature& inc, double cutoff, int feature, bool flip,
               std::vector<RawPoint>& out) {
  std::array<Vector3, kMaxPoly> pts;
  const int n = clipToFace(face, inc, pts);
  int added = 0;
  for (int k = 0; k < n; ++k) {
    const Vector3& x = pts[k];
    const double s = face.normal.dot(x - face.point);
    const double d = s - inc.radius;
    if (d > cutoff) continue;
    const Vector3 pref = x - s * face.normal;
    const Vector3 pinc = x - inc.radius * face.normal;
    if (!flip)
      out.push_back({pref, pinc, face.normal, d, feature});
    else
      out.push_back({pinc, pref, -face.normal, d, feature});
    ++added;
  }
  return added;
}

/// Manifold of a convex pair from its exact normal n (x→y): false when no face is within the
/// face angle or nothing survives the clipping (the caller then keeps the exact point).
bool faceManifold(const ShapeView& x, const ShapeView& y, const Vector3& n, double cutoff,
                  const NarrowSettings& st, std::vector<RawPoint>& out) {
  Feature fx, fy, inc;
  const double ax = faceOf(x, n, fx) ? fx.align : -1.0;
  const double ay = faceOf(y, -n, fy) ? fy.align : -1.0;
  if (std::max(ax, ay) < st.cos_face) return false;
  if (ax >= ay) {
    incidentOf(y, -fx.normal, st.cos_face, inc);
    return facePoints(fx, inc, cutoff, -1, false, out) > 0;
  }
  incidentOf(x, -fy.normal, st.cos_face, inc);
  return facePoints(fy, inc, cutoff, -1, true, out) > 0;
}

Vector3 unitOr(const Vector3& v, const Vector3& fallback) {
  const double n = v.norm();
  if (n > kTiny) return v / n;
  const double m = fallback.norm();
  return m > kTiny ? Vector3(fallback / m) : Vector3(Vector3::UnitZ());
}

fcl::Transform3d toFcl(const SE3& H) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = H.R;
  tf.translation() = H.p;
  return tf;
}

// ---- pairs ----------------------------------------------------------------------------------

void planeConvex(const ShapeView& plane, const ShapeView& y, double cutoff, const NarrowSettings& st,
                 std::vector<RawPoint>& out) {
  Feature face, inc;
  faceOf(plane, Vector3::UnitZ(), face);
  incidentOf(y, -face.normal, st.cos_face, inc);
  facePoints(face, inc, cutoff, -1, false, out);
}

void roundRound(const ShapeView& x, const ShapeView& y, double cutoff, const NarrowSettings& st,
                std::vector<RawPoint>& out) {
  Vector3 xp0, xp1, yp0, yp1, cp, cq;
  core(x, xp0, xp1);
  core(y, yp0, yp1);
  double s, t;
  const double rx = x.shape->radius, ry = y.shape->radius;
  const double dist = closestSegmentSegment(xp0, xp1, yp0, yp1, s, t, cp, cq);
  const double d = dist - rx - ry;
  if (d > cutoff) return;
  const Vector3 n = unitOr(cq - cp, y.oMs.p - x.oMs.p);
  // two capsules side by side: the two ends of their overlap
  const double lx = (xp1 - xp0).norm(), ly = (yp1 - yp0).norm();
  if (lx > kTiny && ly > kTiny) {
    const Vector3 dx = (xp1 - xp0) / lx, dy = (yp1 - yp0) / ly;
    const double sin_max = std::sqrt(std::max(0.0, 1.0 - st.cos_face * st.cos_face));
    if (dx.cross(dy).norm() < sin_max) {
      double t0 = std::clamp(dx.dot(yp0 - xp0), 0.0, lx), t1 = std::clamp(dx.dot(yp1 - xp0), 0.0, lx);
      if (t0 > t1) std::swap(t0, t1);
      if (t1 - t0 > 1e-6) {
        const std::size_t start = out.size();
        for (double tt : {t0, t1}) {
          const Vector3 p = xp0 + tt * dx;
          double u = std::clamp(dy.dot(p - yp0), 0.0, ly);
          const Vector3 q = yp0 + u * dy;
          const double dpq = (q - p).norm();
          if (dpq < 1e-9) {
            out.resize(start);
            break;
          }
          const Vector3 nk = (q - p) / dpq;
          const double dk = dpq - rx - ry;
          if (dk <= cutoff) out.push_back({p + rx * nk, q - ry * nk, nk, dk, -1});
        }
        if (out.size() > start) return;
      }
    }
  }
  out.push_back({cp + rx * n, cq - ry * n, n, d, -1});
}

void boxRound(const ShapeView& box, const ShapeView& y, double cutoff, const NarrowSettings& st,
              std::vector<RawPoint>& out) {
  Vector3 p0, p1;
  core(y, p0, p1);
  const Vector3 half = 0.5 * box.shape->size;
  Vector3 s, surface, normal;
  const double sd = closestSegmentBox(box.oMs.actInv(p0), box.oMs.actInv(p1), half, s, surface, normal);
  const double d = sd - y.shape->radius;
  if (d > cutoff) return;
  const Vector3 n = box.oMs.R * normal;
  if (faceManifold(box, y, n, cutoff, st, out)) return;
  out.push_back({box.oMs.act(surface), box.oMs.act(s) - y.shape->radius * n, n, d, -1});
}

// ---- overlapping convex pairs: separating-axis depth ----------------------------------------
// Penetration depth and witness points of two overlapping convex primitives (box, cylinder, capsule,
// sphere) by the separating-axis test: along a unit direction L from x to y the overlap is
// h_x(L) + h_y(−L) (h the support function); the depth is its minimum over the candidate axes — box face
// normals, the cylinder/capsule axes, their pairwise cross products and the line between the shapes'
// cores. Exact for box–box (the 15 axes of the OBB test); for round shapes an upper bound that is exact
// when the deepest direction is one of the candidates (a face, an end cap, a side). Not libccd's EPA
// (GJKSolver_libccd::shapeSignedDistance): the Debian build of FCL 0.7 keeps its assertions and that EPA
// aborts the process on some overlaps (FCL issue #322, `isOutsidePolytopeFace` in ComputeVisiblePatch);
// nor FCL's own EPA (GJKSolver_indep), which returns wrong depths on overlapping boxes. No allocation.
namespace {

double support(const ShapeView& s, const Vector3& u) {
  const Vector3 c = s.oMs.p;
  const Vector3 a = s.oMs.R.col(2);
  const Shape& sh = *s.shape;
  switch (sh.type) {
    case ShapeType::kBox: {
      double h = c.dot(u);
      for (int i = 0; i < 3; ++i) h += 0.5 * sh.size[i] * std::abs(u.dot(s.oMs.R.col(i)));
      return h;
    }
    case ShapeType::kCylinder: {
      const double ua = u.dot(a);
      return c.dot(u) + 0.5 * sh.length * std::abs(ua) + sh.radius * (u - ua * a).norm();
    }
    case ShapeType::kCapsule: return c.dot(u) + 0.5 * sh.length * std::abs(u.dot(a)) + sh.radius * u.norm();
    case ShapeType::kSphere: return c.dot(u) + sh.radius * u.norm();
    default: return 0.0;
  }
}

// A point of s farthest along u. Along an axis e of s (a box's, a cylinder's or capsule's) that u is
// perpendicular to, every coordinate in [−h, h] is as far: the one nearest `toward` (a point of the
// other shape) is taken, so that an edge or a side touching the other shape gives the contact where they
// meet, not at an end.
double alongAxis(const Vector3& u, const Vector3& e, double h, const Vector3& from_centre) {
  const double ue = u.dot(e);
  if (std::abs(ue) < 1e-9) return std::clamp(from_centre.dot(e), -h, h);
  return ue > 0.0 ? h : -h;
}

Vector3 supportPoint(const ShapeView& s, const Vector3& u, const Vector3& toward) {
  const Vector3 c = s.oMs.p;
  const Vector3 a = s.oMs.R.col(2);
  const Vector3 rel = toward - c;
  const Shape& sh = *s.shape;
  switch (sh.type) {
    case ShapeType::kBox: {
      Vector3 p = c;
      for (int i = 0; i < 3; ++i) p += alongAxis(u, s.oMs.R.col(i), 0.5 * sh.size[i], rel) * s.oMs.R.col(i);
      return p;
    }
    case ShapeType::kCylinder: {
      const double ua = u.dot(a);
      const Vector3 radial = u - ua * a;
      const double rn = radial.norm();
      return c + alongAxis(u, a, 0.5 * sh.length, rel) * a + (rn > kTiny ? Vector3(sh.radius / rn * radial) : Vector3::Zero());
    }
    case ShapeType::kCapsule: return c + alongAxis(u, a, 0.5 * sh.length, rel) * a + sh.radius * u;
    case ShapeType::kSphere: return c + sh.radius * u;
    default: return c;
  }
}

bool hasAxis(const ShapeView& s) { return s.shape->type == ShapeType::kCylinder || s.shape->type == ShapeType::kCapsule; }

}  // namespace

bool satPenetration(const ShapeView& x, const ShapeView& y, double& d, Vector3& p1, Vector3& p2) {
  std::array<Vector3, 32> axes;
  std::size_t n = 0;
  const auto dirs = [&](const ShapeView& s, std::array<Vector3, 3>& out) -> int {
    if (s.shape->type == ShapeType::kBox) {
      for (int i = 0; i < 3; ++i) out[static_cast<std::size_t>(i)] = s.oMs.R.col(i);
      return 3;
    }
    if (hasAxis(s)) {
      out[0] = s.oMs.R.col(2);
      return 1;
    }
    return 0;
  };
  std::array<Vector3, 3> dx, dy;
  const int nx = dirs(x, dx), ny = dirs(y, dy);
  for (int i = 0; i < nx; ++i) axes[n++] = dx[static_cast<std::size_t>(i)];
  for (int j = 0; j < ny; ++j) axes[n++] = dy[static_cast<std::size_t>(j)];
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const Vector3 c = dx[static_cast<std::size_t>(i)].cross(dy[static_cast<std::size_t>(j)]);
      if (c.norm() > 1e-9) axes[n++] = c.normalized();
    }
  // the line between the cores (closest points of the axes' segments, or the centres)
  Vector3 cq = y.oMs.p;
  {
    Vector3 x0, x1, y0, y1, cp;
    const auto seg = [](const ShapeView& s, Vector3& a, Vector3& b) {
      const double h = hasAxis(s) ? 0.5 * s.shape->length : 0.0;
      a = s.oMs.act(Vector3(0, 0, -h));
      b = s.oMs.act(Vector3(0, 0, h));
    };
    seg(x, x0, x1);
    seg(y, y0, y1);
    double ss, tt;
    closestSegmentSegment(x0, x1, y0, y1, ss, tt, cp, cq);
    if ((cq - cp).norm() > 1e-9) axes[n++] = (cq - cp).normalized();
    // and from the core of a round shape to its radial direction about the other's axis
    for (const auto& [a, b] : {std::make_pair(&x, &y), std::make_pair(&y, &x)})
      if (hasAxis(*a)) {
        const Vector3 ax = a->oMs.R.col(2);
        Vector3 r = b->oMs.p - a->oMs.p;
        r -= r.dot(ax) * ax;
        if (r.norm() > 1e-9) axes[n++] = r.normalized();
      }
  }
  if (n == 0) axes[n++] = Vector3::UnitZ();  // two spheres at one centre
  double best = std::numeric_limits<double>::infinity();
  Vector3 best_u = Vector3::UnitZ();
  for (std::size_t k = 0; k < n; ++k)
    for (const double sign : {1.0, -1.0}) {
      const Vector3 u = sign * axes[k];  // from x to y
      const double overlap = support(x, u) + support(y, -u);
      if (overlap < best) {
        best = overlap;
        best_u = u;
      }
    }
  if (!std::isfinite(best)) return false;
  // best < 0: a separating axis after all (GJK's "touching" within its tolerance): apart by −best at most
  d = -best;
  p1 = supportPoint(x, best_u, cq);  // x's deepest point into y (ties: nearest y's core)
  p2 = p1 - best * best_u;           // where it must go to touch y's surface
  return p1.allFinite() && p2.allFinite();
}

// Closest points of two convex shapes: libccd's GJK when they are apart (no EPA), else satPenetration().
template <typename SX, typename SY>
bool gjk(const ShapeView& x, const ShapeView& y, NarrowScratch& sc, double& d, Vector3& p1, Vector3& p2) {
  if (sc.gjk.shapeDistance(*static_cast<const SX*>(x.geometry), toFcl(x.oMs), *static_cast<const SY*>(y.geometry),
                           toFcl(y.oMs), &d, &p1, &p2) &&
      d > 0.0)
    return true;
  if (satPenetration(x, y, d, p1, p2)) return true;
  throw std::runtime_error("collision: no depth for an overlapping pair");  // counted as a failed pair
}

template <typename SX>
bool gjkY(const ShapeView& x, const ShapeView& y, NarrowScratch& sc, double& d, Vector3& p1, Vector3& p2) {
  switch (y.shape->type) {
    case ShapeType::kBox: return gjk<SX, fcl::Boxd>(x, y, sc, d, p1, p2);
    case ShapeType::kCylinder: return gjk<SX, fcl::Cylinderd>(x, y, sc, d, p1, p2);
    case ShapeType::kCapsule: return gjk<SX, fcl::Capsuled>(x, y, sc, d, p1, p2);
    case ShapeType::kSphere: return gjk<SX, fcl::Sphered>(x, y, sc, d, p1, p2);
    default: return false;
  }
}

// bounding-sphere radius of a convex primitive about its frame origin
double boundRadius(const Shape& s) {
  switch (s.type) {
    case ShapeType::kBox: return 0.5 * s.size.norm();
    case ShapeType::kCylinder: return std::hypot(s.radius, 0.5 * s.length);
    case ShapeType::kCapsule: return s.radius + 0.5 * s.length;
    case ShapeType::kSphere: return s.radius;
    default: return 1e300;
  }
}

void convexGjk(const ShapeView& x, const ShapeView& y, double cutoff, const NarrowSettings& st,
               NarrowScratch& sc, std::vector<RawPoint>& out) {
  if ((x.oMs.p - y.oMs.p).norm() - boundRadius(*x.shape) - boundRadius(*y.shape) > cutoff) return;
  double d = 0.0;
  Vector3 p1 = Vector3::Zero(), p2 = Vector3::Zero();
  bool ok = false;
  if (x.shape->type == ShapeType::kBox)
    ok = gjkY<fcl::Boxd>(x, y, sc, d, p1, p2);
  else if (x.shape->type == ShapeType::kCylinder)
    ok = gjkY<fcl::Cylinderd>(x, y, sc, d, p1, p2);
  if (!ok && d >= 0.0) return;
  if (!std::isfinite(d) || !p1.allFinite() || !p2.allFinite()) return;
  if (d > cutoff) return;
  const Vector3 n = d >= 0.0 ? unitOr(p2 - p1, y.oMs.p - x.oMs.p) : unitOr(p1 - p2, y.oMs.p - x.oMs.p);
  if (faceManifold(x, y, n, cutoff, st, out)) return;
  out.push_back({p1, p2, n, d, -1});
}

// ---- meshes ---------------------------------------------------------------------------------

void meshConvex(const ShapeView& mesh, const ShapeView& y, double cutoff, const NarrowSettings& st,
                NarrowScratch& sc, std::vector<RawPoint>& out) {
  const auto& bvh = *mesh.bvh;
  // y in the mesh frame
  const SE3 mMy = mesh.oMs.inverse() * y.oMs;
  const ShapeView yl{y.shape, mMy, y.geometry, nullptr};
  fcl::OBBd query;
  const Shape& ys = *y.shape;
  const bool round = ys.type == ShapeType::kCapsule || ys.type == ShapeType::kSphere;
  Vector3 p0 = Vector3::Zero(), p1 = Vector3::Zero();
  if (round) core(yl, p0, p1);
  {
    query.axis = mMy.R;
    query.To = mMy.p;
    const double c = cutoff;
    switch (ys.type) {
      case ShapeType::kBox: query.extent = 0.5 * ys.size + Vector3::Constant(c); break;
      case ShapeType::kCylinder:
        query.extent = Vector3(ys.radius + c, ys.radius + c, 0.5 * ys.length + c);
        break;
      default:
        query.extent = Vector3(ys.radius + c, ys.radius + c, 0.5 * ys.length + ys.radius + c);
        if (ys.type == ShapeType::kSphere) query.extent.z() = ys.radius + c;
        break;
    }
  }
  const std::size_t start = out.size();
  auto& stack = sc.stack;
  stack.clear();
  stack.push_back(0);
  Feature inc, face;
  while (!stack.empty()) {
    const int id = stack.back();
    stack.pop_back();
    const auto& node = bvh.getBV(id);
    if (!node.bv.obb.overlap(query)) continue;
    if (!node.isLeaf()) {
      stack.push_back(node.rightChild());
      stack.push_back(node.leftChild());  // left first
      continue;
    }
    const int tri = node.primitiveId();
    ++sc.triangles_tested;
    const fcl::Triangle& t = bvh.tri_indices[tri];
    const Vector3& a = bvh.vertices[t[0]];
    const Vector3& b = bvh.vertices[t[1]];
    const Vector3& c = bvh.vertices[t[2]];
    Vector3 nt = (b - a).cross(c - a);
    const double area2 = nt.norm();
    if (area2 < kTiny) continue;
    nt /= area2;
    face.v[0] = a;
    face.v[1] = b;
    face.v[2] = c;
    face.n = 3;
    face.point = a;
    face.infinite = false;
    if (round) {
      // bounding sphere of the triangle against the segment: cheap rejection
      const Vector3 g = (a + b + c) / 3.0;
      const double rg = std::sqrt(std::max({(a - g).squaredNorm(), (b - g).squaredNorm(), (c - g).squaredNorm()}));
      const Vector3 seg = p1 - p0;
      const double ls = seg.squaredNorm();
      const double tg = ls > 0.0 ? std::clamp(seg.dot(g - p0) / ls, 0.0, 1.0) : 0.0;
      if ((p0 + tg * seg - g).norm() - rg - ys.radius > cutoff) continue;
      Vector3 cs, ct;
      const double dist = closestSegmentTriangle(p0, p1, a, b, c, cs, ct);
      const double d = dist - ys.radius;
      if (d > cutoff) continue;
      Vector3 u;
      if (dist > 1e-9) {
        u = (cs - ct) / dist;
        if (nt.dot(u) < 0.0) nt = -nt;
      } else {
        if (nt.dot(0.5 * (p0 + p1) - ct) < 0.0) nt = -nt;
        u = nt;
      }
      face.normal = nt;
      if (nt.dot(u) >= st.cos_face) {
        incidentOf(yl, -nt, st.cos_face, inc);
        if (facePoints(face, inc, cutoff, tri, false, out) > 0) continue;
      }
      out.push_back({ct, cs - ys.radius * u, u, d, tri});
    } else {
      // box or cylinder: the face manifold against the triangle (normal towards y's centre)
      if (nt.dot(mMy.p - a) < 0.0) nt = -nt;
      face.normal = nt;
      incidentOf(yl, -nt, st.cos_face, inc);
      if (facePoints(face, inc, cutoff, tri, false, out) > 0) continue;
      double dist = 0.0;
      Vector3 q1, q2;
      bool ok = false;
      const fcl::Transform3d tf = toFcl(mMy);
      if (ys.type == ShapeType::kBox)
        ok = sc.gjk.shapeTriangleDistance(*static_cast<const fcl::Boxd*>(y.geometry), tf, a, b, c, &dist, &q1, &q2);
      else
        ok = sc.gjk.shapeTriangleDistance(*static_cast<const fcl::Cylinderd*>(y.geometry), tf, a, b, c, &dist, &q1, &q2);
      if (!ok || dist > cutoff || !q1.allFinite() || !q2.allFinite()) continue;
      const Vector3 u = unitOr(q1 - q2, nt);
      out.push_back({q2, q1, u, dist, tri});
    }
  }
  // back to the world frame
  for (std::size_t k = start; k < out.size(); ++k) {
    out[k].px = mesh.oMs.act(out[k].px);
    out[k].py = mesh.oMs.act(out[k].py);
    out[k].n = mesh.oMs.R * out[k].n;
  }
}

// ---- manifold reduction -----------------------------------------------------------------------

double triArea(const Vector3& a, const Vector3& b, const Vector3& c) { return (b - a).cross(c - a).norm(); }

void reduce(std::vector<RawPoint>& out, std::size_t start, int max_points, NarrowScratch& sc) {
  const int n = static_cast<int>(out.size() - start);
  const RawPoint* pts = out.data() + start;
  auto same = [](const RawPoint& a, const RawPoint& b) {
    return (a.px - b.px).squaredNorm() < 1e-12 && (a.py - b.py).squaredNorm() < 1e-12;
  };
  auto& red = sc.reduced;
  red.clear();
  if (n <= max_points) {  // few points: only drop duplicates
    for (int k = 0; k < n; ++k) {
      bool dup = false;
      for (const auto& r : red) dup = dup || same(r, pts[k]);
      if (!dup) red.push_back(pts[k]);
    }
  } else {
    // deepest, then farthest from it, then largest triangle, then largest added area; a point
    // that adds nothing (duplicate, collinear) is never picked. O(n · max_points).
    std::array<int, 8> sel{};
    auto& used = sc.used;
    used.assign(n, 0);
    int best = 0;
    for (int k = 1; k < n; ++k)
      if (pts[k].d < pts[best].d) best = k;
    sel[0] = best;
    used[best] = 1;
    int count = 1;
    auto pick = [&](auto score) {
      int arg = -1;
      double top = 1e-12;
      for (int k = 0; k < n; ++k) {
        if (used[k]) continue;
        const double v = score(pts[k].py);
        if (v > top) {
          top = v;
          arg = k;
        }
      }
      if (arg < 0) return false;
      used[arg] = 1;
      sel[count++] = arg;
      return true;
    };
    bool more = max_points >= 2 && pick([&](const Vector3& p) { return (p - pts[sel[0]].py).squaredNorm(); });
    if (more && max_points >= 3)
      more = pick([&](const Vector3& p) { return triArea(pts[sel[0]].py, pts[sel[1]].py, p); });
    while (more && count < max_points) {
      more = pick([&](const Vector3& p) {
        double s = 0.0;
        for (int k = 0; k < count; ++k) s += triArea(pts[sel[k]].py, pts[sel[(k + 1) % count]].py, p);
        return s - triArea(pts[sel[0]].py, pts[sel[1]].py, pts[sel[2]].py);
      });
    }
    for (int i = 1; i < count; ++i)  // keep generation order (insertion sort)
      for (int k = i; k > 0 && sel[k - 1] > sel[k]; --k) std::swap(sel[k - 1], sel[k]);
    for (int k = 0; k < count; ++k) red.push_back(pts[sel[k]]);
  }
  out.resize(start);
  out.insert(out.end(), red.begin(), red.end());
}

}  // namespace

void narrowPhase(const ShapeView& x, const ShapeView& y, double cutoff, const NarrowSettings& st,
                 NarrowScratch& sc, std::vector<RawPoint>& out) {
  const std::size_t start = out.size();
  const ShapeType tx = x.shape->type, ty = y.shape->type;
  const bool round_y = ty == ShapeType::kCapsule || ty == ShapeType::kSphere;
  if (tx == ShapeType::kPlane) {
    if (ty == ShapeType::kPlane || ty == ShapeType::kMesh) {
      ++sc.unsupported_pairs;
      return;
    }
    planeConvex(x, y, cutoff, st, out);
  } else if (tx == ShapeType::kMesh) {
    if (ty == ShapeType::kMesh) {
      ++sc.unsupported_pairs;
      return;
    }
    meshConvex(x, y, cutoff, st, sc, out);
  } else if (tx == ShapeType::kBox && round_y) {
    boxRound(x, y, cutoff, st, out);
  } else if (round_y && (tx == ShapeType::kCapsule || tx == ShapeType::kSphere)) {
    roundRound(x, y, cutoff, st, out);
  } else {
    convexGjk(x, y, cutoff, st, sc, out);
  }
  if (out.size() > start) reduce(out, start, st.max_points, sc);
}

}  // namespace mannequin::collision::detail
