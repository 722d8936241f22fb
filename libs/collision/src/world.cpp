#include "mannequin/collision/world.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/halfspace.h>
#include <fcl/geometry/shape/sphere.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "mannequin/collision/geometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "mannequin/math/frame.hpp"
#include "narrowphase.hpp"

namespace mannequin::collision {

using math::Matrix3;

namespace {

/// An FCL collision object whose world AABB we set ourselves (tight and inflated).
class BroadObject : public fcl::CollisionObjectd {
 public:
  using fcl::CollisionObjectd::CollisionObjectd;
  void setAabb(const Vector3& lo, const Vector3& hi) {
    aabb.min_ = lo;
    aabb.max_ = hi;
  }
};

struct Collider {
  int body = -1;
  int shape_index = 0;
  Shape shape;
  SE3 bMs;  ///< shape in body
  SE3 oMs;  ///< shape in world
  std::shared_ptr<fcl::CollisionGeometryd> geometry;
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> bvh;
  std::unique_ptr<BroadObject> object;
  Vector3 local_lo = Vector3::Zero(), local_hi = Vector3::Zero();  ///< mesh bounds, shape frame
};

struct Body {
  std::string name;
  BodyKind kind = BodyKind::kStatic;
  SE3 oMb;
  double margin = 0.0;
  int mannequin = -1;
  int segment = -1;
  std::vector<int> colliders;
  std::uint64_t ignored_mannequins = 0;  ///< bit m: no pair with mannequin m's segments (setIgnoresMannequin)
};

struct MannequinEntry {
  std::string name;
  int njoints = 0;
  std::vector<int> segment_body;   ///< body id per segment (−1: none)
  std::vector<int> segment_joint;
  bool self_collision = true;
  bool placed = true;              ///< false: pairs only with static bodies and itself
  std::vector<char> excluded;      ///< nseg × nseg
};

constexpr double kBig = 1e6;

using math::frameAlong;

}  // namespace

struct CollisionWorld::Impl {
  WorldOptions options;
  std::vector<Body> bodies;
  std::vector<Collider> colliders;
  std::vector<MannequinEntry> mannequins;
  std::map<std::string, int> by_name;

  fcl::DynamicAABBTreeCollisionManagerd static_mgr, dynamic_mgr;
  bool dirty = true;  ///< managers must be rebuilt
  /// Some pair of moving bodies may collide (pairEnabled): else the moving bodies' tree is not
  /// collided with itself (one mannequin without self collision, no movable object). Set by rebuild().
  bool dynamic_pairs = true;

  std::vector<std::pair<int, int>> candidates;  ///< collider pairs
  detail::NarrowScratch scratch;
  std::vector<detail::RawPoint> raw;

  double inflation(const Collider& c) const {
    return bodies[c.body].margin + 0.5 * options.activation_distance;
  }

  void computeAabb(Collider& c) const {
    const double inf = inflation(c);
    const Shape& s = c.shape;
    const Matrix3& R = c.oMs.R;
    const Vector3& p = c.oMs.p;
    Vector3 half = Vector3::Zero();
    Vector3 center = p;
    switch (s.type) {
      case ShapeType::kSphere: half = Vector3::Constant(s.radius); break;
      case ShapeType::kCapsule:
        half = (0.5 * s.length) * R.col(2).cwiseAbs() + Vector3::Constant(s.radius);
        break;
      case ShapeType::kBox: half = R.cwiseAbs() * (0.5 * s.size); break;
      case ShapeType::kCylinder:
        half = R.cwiseAbs() * Vector3(s.radius, s.radius, 0.5 * s.length);
        break;
      case ShapeType::kMesh:
        center = c.oMs.act(0.5 * (c.local_lo + c.local_hi));
        half = R.cwiseAbs() * (0.5 * (c.local_hi - c.local_lo));
        break;
      case ShapeType::kPlane: {
        // half-space n·x ≤ o: bounded along an axis-aligned normal only
        const Vector3 n = R * s.normal;
        const double o = s.offset + n.dot(p);
        Vector3 lo = Vector3::Constant(-kBig), hi = Vector3::Constant(kBig);
        for (int k = 0; k < 3; ++k) {
          if (n[k] > 1.0 - 1e-12) hi[k] = o + inf;
          if (n[k] < -1.0 + 1e-12) lo[k] = -o - inf;
        }
        c.object->setAabb(lo, hi);
        return;
      }
    }
    const Vector3 e = half + Vector3::Constant(inf);
    c.object->setAabb(center - e, center + e);
  }

  bool pairEnabled(int a, int b) const {
    if (a == b) return false;
    const Body& A = bodies[a];
    const Body& B = bodies[b];
    if (A.kind == BodyKind::kStatic && B.kind == BodyKind::kStatic) return false;
    if (A.mannequin >= 0 && A.mannequin == B.mannequin) {
      const auto& m = mannequins[A.mannequin];
      if (!m.self_collision) return false;
      const int n = static_cast<int>(m.segment_body.size());
      return !m.excluded[A.segment * n + B.segment];
    }
    return true;
  }

  /// False when one body is a segment of a mannequin that is not placed and the other is neither
  /// static nor of the same mannequin.
  bool placedPair(int a, int b) const {
    const Body& A = bodies[a];
    const Body& B = bodies[b];
    if ((B.mannequin >= 0 && B.mannequin < 64 && (A.ignored_mannequins >> B.mannequin & 1u) != 0) ||
        (A.mannequin >= 0 && A.mannequin < 64 && (B.ignored_mannequins >> A.mannequin & 1u) != 0))
      return false;  // e.g. a held object and the mannequin holding it: not even a narrow phase
    if (A.mannequin == B.mannequin) return true;
    const auto unplaced = [&](const Body& X, const Body& Y) {
      return X.mannequin >= 0 && !mannequins[X.mannequin].placed && Y.kind != BodyKind::kStatic;
    };
    return !unplaced(A, B) && !unplaced(B, A);
  }

  void rebuild() {
    static_mgr.clear();
    dynamic_mgr.clear();
    std::vector<fcl::CollisionObjectd*> stat, dyn;
    for (auto& c : colliders) {
      computeAabb(c);
      (bodies[c.body].kind == BodyKind::kStatic ? stat : dyn).push_back(c.object.get());
    }
    static_mgr.registerObjects(stat);
    dynamic_mgr.registerObjects(dyn);
    static_mgr.setup();
    dynamic_mgr.setup();
    dynamic_pairs = false;
    const int nb = static_cast<int>(bodies.size());
    for (int a = 0; a < nb && !dynamic_pairs; ++a) {
      if (bodies[a].kind == BodyKind::kStatic || bodies[a].colliders.empty()) continue;
      for (int b = a + 1; b < nb && !dynamic_pairs; ++b)
        dynamic_pairs = bodies[b].kind != BodyKind::kStatic && !bodies[b].colliders.empty() && pairEnabled(a, b);
    }
    dirty = false;
  }

  static bool onPair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    auto* self = static_cast<Impl*>(data);
    int i = static_cast<int>(reinterpret_cast<std::intptr_t>(o1->getUserData()));
    int j = static_cast<int>(reinterpret_cast<std::intptr_t>(o2->getUserData()));
    const int bi = self->colliders[i].body, bj = self->colliders[j].body;
    if (!self->pairEnabled(bi, bj) || !self->placedPair(bi, bj)) return false;
    if (bi > bj || (bi == bj && i > j)) std::swap(i, j);
    self->candidates.emplace_back(i, j);
    return false;  // go on
  }

  int addCollider(int body, const PlacedShape& ps) {
    Collider c;
    c.body = body;
    c.shape_index = static_cast<int>(bodies[body].colliders.size());
    c.shape = ps.shape;
    c.bMs = ps.pose;
    c.oMs = bodies[body].oMb * ps.pose;
    const Shape& s = ps.shape;
    switch (s.type) {
      case ShapeType::kSphere: c.geometry = std::make_shared<fcl::Sphered>(s.radius); break;
      case ShapeType::kCapsule: c.geometry = std::make_shared<fcl::Capsuled>(s.radius, s.length); break;
      case ShapeType::kBox: c.geometry = std::make_shared<fcl::Boxd>(s.size); break;
      case ShapeType::kCylinder: c.geometry = std::make_shared<fcl::Cylinderd>(s.radius, s.length); break;
      case ShapeType::kPlane: c.geometry = std::make_shared<fcl::Halfspaced>(s.normal, s.offset); break;
      case ShapeType::kMesh: {
        auto bvh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
        const auto& m = *s.mesh;
        std::vector<fcl::Triangle> tris;
        tris.reserve(m.triangles.size());
        for (const auto& t : m.triangles) tris.emplace_back(t[0], t[1], t[2]);
        bvh->beginModel(static_cast<int>(tris.size()), static_cast<int>(m.vertices.size()));
        bvh->addSubModel(m.vertices, tris);
        bvh->endModel();
        bvh->computeLocalAABB();
        c.bvh = bvh;
        c.geometry = bvh;
        m.bounds(c.local_lo, c.local_hi);
        break;
      }
    }
    c.object = std::make_unique<BroadObject>(c.geometry);
    const int id = static_cast<int>(colliders.size());
    c.object->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(id)));
    colliders.push_back(std::move(c));
    bodies[body].colliders.push_back(id);
    dirty = true;
    return id;
  }

  detail::ShapeView view(const Collider& c) const {
    return {&c.shape, c.oMs, c.geometry.get(), c.bvh.get()};
  }

  void checkBody(int body) const {
    if (body < 0 || body >= static_cast<int>(bodies.size()))
      throw std::invalid_argument("unknown body id " + std::to_string(body));
  }
};

CollisionWorld::CollisionWorld(const WorldOptions& options) : impl_(std::make_unique<Impl>()) {
  if (!std::isfinite(options.activation_distance) || options.activation_distance < 0.0)
    throw std::invalid_argument("WorldOptions.activation_distance must be finite and >= 0");
  if (options.max_points_per_pair < 1 || options.max_points_per_pair > 8)
    throw std::invalid_argument("WorldOptions.max_points_per_pair must be in [1, 8]");
  if (!(options.face_angle_deg >= 0.0 && options.face_angle_deg < 90.0))
    throw std::invalid_argument("WorldOptions.face_angle_deg must be in [0, 90)");
  impl_->options = options;
}
CollisionWorld::~CollisionWorld() = default;
CollisionWorld::CollisionWorld(CollisionWorld&&) noexcept = default;
CollisionWorld& CollisionWorld::operator=(CollisionWorld&&) noexcept = default;

void CollisionWorld::addScene(const SceneSpec& scene) {
  if (scene.activation_distance >= 0.0) impl_->options.activation_distance = scene.activation_distance;
  for (const auto& b : scene.bodies) {
    addBody("scene/" + b.name, b.shapes, b.pose, b.movable ? BodyKind::kMovable : BodyKind::kStatic,
            b.margin >= 0.0 ? b.margin : scene.margin);
  }
}

int CollisionWorld::addBody(const std::string& name, const std::vector<PlacedShape>& shapes, const SE3& pose,
                   BodyKind kind, double margin) {
  auto& I = *impl_;
  if (name.empty()) throw std::invalid_argument("body name is empty");
  if (I.by_name.count(name)) throw std::invalid_argument("duplicate body name '" + name + "'");
  if (shapes.empty()) throw std::invalid_argument("body '" + name + "' has no shape");
  if (!std::isfinite(margin) || margin < 0.0)
    throw std::invalid_argument("body '" + name + "': margin must be finite and >= 0");
  if (!pose.allFinite()) throw std::invalid_argument("body '" + name + "': pose is not finite");
  for (const auto& s : shapes)
    if (!s.pose.allFinite()) throw std::invalid_argument("body '" + name + "': shape pose is not finite");
  const int id = static_cast<int>(I.bodies.size());
  Body b;
  b.name = name;
  b.kind = kind;
  b.oMb = pose;
  b.margin = margin;
  I.bodies.push_back(std::move(b));
  I.by_name[name] = id;
  for (const auto& s : shapes) I.addCollider(id, s);
  return id;
}

int CollisionWorld::addMannequin(const skeleton::Model& model, const MannequinOptions& opt) {
  auto& I = *impl_;
  const int index = static_cast<int>(I.mannequins.size());
  MannequinEntry m;
  m.name = opt.name.empty() ? "mannequin" + std::to_string(index) : opt.name;
  m.njoints = static_cast<int>(model.joints.size());
  m.self_collision = opt.self_collision;
  const int nseg = static_cast<int>(model.segments.size());
  m.segment_body.assign(nseg, -1);
  m.segment_joint.resize(nseg);
  m.excluded.assign(static_cast<std::size_t>(nseg) * nseg, 0);
  if (!std::isfinite(opt.margin) || opt.margin < 0.0)
    throw std::invalid_argument("MannequinOptions.margin must be finite and >= 0");
  for (int i = 0; i < nseg; ++i) m.segment_joint[i] = model.segments[i].joint;
  // the segment of each joint (first one), then each segment's parent segment
  std::vector<int> joint_segment(model.joints.size(), -1);
  for (int i = nseg - 1; i >= 0; --i) joint_segment[m.segment_joint[i]] = i;
  auto parentSegment = [&](int i) {
    for (int j = model.joints[m.segment_joint[i]].parent; j >= 0; j = model.joints[j].parent)
      if (joint_segment[j] >= 0) return joint_segment[j];
    return -1;
  };
  for (int i = 0; i < nseg; ++i)
    for (int j = 0; j < nseg; ++j) {
      const bool adjacent = m.segment_joint[i] == m.segment_joint[j] || parentSegment(i) == j ||
                            parentSegment(j) == i;
      if (i == j || (opt.exclude_adjacent && adjacent)) m.excluded[i * nseg + j] = 1;
    }
  for (const auto& [a, b] : opt.exclude_pairs) {
    const int ia = model.findSegment(a), ib = model.findSegment(b);
    if (ia < 0 || ib < 0)
      throw std::invalid_argument("MannequinOptions.exclude_pairs: unknown segment '" + (ia < 0 ? a : b) +
                                  "' in mannequin '" + model.name + "'");
    m.excluded[ia * nseg + ib] = m.excluded[ib * nseg + ia] = 1;
  }
  I.mannequins.push_back(m);
  for (int i = 0; i < nseg; ++i) {
    const auto& seg = model.segments[i];
    const auto& cap = seg.capsule;
    if (!(cap.radius > 0.0)) continue;
    PlacedShape ps;
    const Vector3 dir = cap.b - cap.a;
    const double len = dir.norm();
    ps.pose.p = 0.5 * (cap.a + cap.b);
    ps.pose.R = len > 1e-12 ? frameAlong(dir) : Matrix3::Identity();
    const bool foot = opt.foot_boxes && seg.name.rfind("foot", 0) == 0;
    ps.shape = foot ? Shape::box(Vector3(2 * cap.radius, 2 * cap.radius, len + 2 * cap.radius))
                    : Shape::capsule(cap.radius, len);
    const int body = addBody(m.name + "/" + seg.name, {ps}, SE3::Identity(), BodyKind::kSegment, opt.margin);
    I.bodies[body].mannequin = index;
    I.bodies[body].segment = i;
    I.mannequins[index].segment_body[i] = body;
  }
  if (opt.exclude_touching_at_neutral) {
    skeleton::Data data(model);
    skeleton::forwardKinematics(model, data, model.neutralConfiguration());
    updateMannequin(index, data);
    auto& me = I.mannequins[index];
    detail::NarrowSettings st;
    for (int i = 0; i < nseg; ++i)
      for (int j = i + 1; j < nseg; ++j) {
        const int bi = me.segment_body[i], bj = me.segment_body[j];
        if (bi < 0 || bj < 0 || me.excluded[i * nseg + j]) continue;
        const Collider& ci = I.colliders[I.bodies[bi].colliders[0]];
        const Collider& cj = I.colliders[I.bodies[bj].colliders[0]];
        const bool swap = static_cast<int>(ci.shape.type) > static_cast<int>(cj.shape.type);
        I.raw.clear();
        detail::narrowPhase(I.view(swap ? cj : ci), I.view(swap ? ci : cj), 0.0, st, I.scratch, I.raw);
        if (!I.raw.empty()) me.excluded[i * nseg + j] = me.excluded[j * nseg + i] = 1;
      }
  }
  return index;
}

void CollisionWorld::setBodyPose(int body, const SE3& oMb) {
  auto& I = *impl_;
  I.checkBody(body);
  Body& b = I.bodies[body];
  if (b.kind != BodyKind::kMovable)
    throw std::invalid_argument("body '" + b.name + "' is not movable (static or a mannequin segment)");
  if (!oMb.allFinite()) throw std::invalid_argument("body '" + b.name + "': pose is not finite");
  b.oMb = oMb;
  for (int c : b.colliders) I.colliders[c].oMs = oMb * I.colliders[c].bMs;
}

void CollisionWorld::updateMannequin(int mannequin, const skeleton::Data& data) {
  auto& I = *impl_;
  if (mannequin < 0 || mannequin >= static_cast<int>(I.mannequins.size()))
    throw std::invalid_argument("unknown mannequin " + std::to_string(mannequin));
  const auto& m = I.mannequins[mannequin];
  if (static_cast<int>(data.oMi.size()) != m.njoints)
    throw std::invalid_argument("mannequin '" + m.name + "': data has " + std::to_string(data.oMi.size()) +
                                " joints, model " + std::to_string(m.njoints));
  for (std::size_t i = 0; i < m.segment_body.size(); ++i) {
    const int body = m.segment_body[i];
    if (body < 0) continue;
    Body& b = I.bodies[body];
    b.oMb = data.oMi[m.segment_joint[i]];
    for (int c : b.colliders) I.colliders[c].oMs = b.oMb * I.colliders[c].bMs;
  }
}

void CollisionWorld::setMargin(int body, double margin) {
  impl_->checkBody(body);
  if (!std::isfinite(margin) || margin < 0.0) throw std::invalid_argument("margin must be finite and >= 0");
  impl_->bodies[body].margin = margin;
  impl_->dirty = true;
}

void CollisionWorld::setIgnoresMannequin(int body, int mannequin, bool ignore) {
  if (body < 0 || body >= bodyCount()) throw std::invalid_argument("collision: setIgnoresMannequin: no body " + std::to_string(body));
  if (mannequin < 0 || mannequin >= mannequinCount() || mannequin >= 64)
    throw std::invalid_argument("collision: setIgnoresMannequin: no mannequin " + std::to_string(mannequin) + " (at most 64)");
  std::uint64_t& m = impl_->bodies[static_cast<std::size_t>(body)].ignored_mannequins;
  const std::uint64_t bit = std::uint64_t{1} << mannequin;
  m = ignore ? (m | bit) : (m & ~bit);
}

bool CollisionWorld::ignoresMannequin(int body, int mannequin) const {
  if (body < 0 || body >= bodyCount() || mannequin < 0 || mannequin >= 64) return false;
  return (impl_->bodies[static_cast<std::size_t>(body)].ignored_mannequins >> mannequin & 1u) != 0;
}

void CollisionWorld::query(std::uint64_t step, ContactSet& out) {
  auto& I = *impl_;
  out.step = step;
  out.contacts.clear();
  out.stats = {};
  if (I.dirty) I.rebuild();
  // refit the moving colliders' inflated AABBs
  bool any_dynamic = false;
  for (auto& c : I.colliders) {
    if (I.bodies[c.body].kind == BodyKind::kStatic) continue;
    I.computeAabb(c);
    any_dynamic = true;
  }
  if (any_dynamic) I.dynamic_mgr.update();
  I.candidates.clear();
  I.dynamic_mgr.collide(&I.static_mgr, &I, &Impl::onPair);
  if (I.dynamic_pairs) I.dynamic_mgr.collide(&I, &Impl::onPair);
  // deterministic order whatever the trees' shapes
  std::sort(I.candidates.begin(), I.candidates.end(), [&](const auto& u, const auto& v) {
    const Collider& a0 = I.colliders[u.first];
    const Collider& b0 = I.colliders[u.second];
    const Collider& a1 = I.colliders[v.first];
    const Collider& b1 = I.colliders[v.second];
    if (a0.body != a1.body) return a0.body < a1.body;
    if (b0.body != b1.body) return b0.body < b1.body;
    if (a0.shape_index != a1.shape_index) return a0.shape_index < a1.shape_index;
    return b0.shape_index < b1.shape_index;
  });
  out.stats.broadphase_pairs = static_cast<int>(I.candidates.size());
  I.scratch.triangles_tested = 0;
  detail::NarrowSettings st;
  st.cos_face = std::cos(I.options.face_angle_deg * 3.14159265358979323846 / 180.0);
  st.max_points = I.options.max_points_per_pair;
  for (const auto& [ia, ib] : I.candidates) {
    const Collider& ca = I.colliders[ia];
    const Collider& cb = I.colliders[ib];
    const Body& A = I.bodies[ca.body];
    const Body& B = I.bodies[cb.body];
    const double cutoff = I.options.activation_distance + A.margin + B.margin;
    // narrow phase in canonical type order x ≤ y
    const bool swap = static_cast<int>(ca.shape.type) > static_cast<int>(cb.shape.type);
    const Collider& cx = swap ? cb : ca;
    const Collider& cy = swap ? ca : cb;
    I.raw.clear();
    try {
      detail::narrowPhase(I.view(cx), I.view(cy), cutoff, st, I.scratch, I.raw);
    } catch (const std::exception&) {
      // FCL's GJK/EPA can give up on degenerate configurations (two coincident boxes): the pair gets
      // no contact this query, counted, instead of ending the caller's loop
      ++out.stats.failed_pairs;
      continue;
    }
    if (I.raw.empty()) continue;
    ++out.stats.pairs_in_range;
    const std::size_t first = out.contacts.size();
    const SE3 aMo = A.oMb.inverse(), bMo = B.oMb.inverse();
    for (const auto& r : I.raw) {
      Contact c;
      c.body_a = ca.body;
      c.body_b = cb.body;
      c.shape_a = ca.shape_index;
      c.shape_b = cb.shape_index;
      c.feature = r.feature;
      const Vector3 n = swap ? Vector3(-r.n) : r.n;
      const Vector3& pa = swap ? r.py : r.px;
      const Vector3& pb = swap ? r.px : r.py;
      c.normal = n;
      c.distance = r.d - A.margin - B.margin;
      c.point_a = aMo.act(pa + A.margin * n);
      c.point_b = bMo.act(pb - B.margin * n);
      out.contacts.push_back(c);
    }
    // by feature, stable (insertion sort: a pair has a few points, and std::stable_sort allocates)
    for (std::size_t i = first + 1; i < out.contacts.size(); ++i)
      for (std::size_t j = i; j > first && out.contacts[j].feature < out.contacts[j - 1].feature; --j)
        std::swap(out.contacts[j], out.contacts[j - 1]);
  }
  out.stats.triangles_tested = I.scratch.triangles_tested;
}

void CollisionWorld::setMannequinPlaced(int mannequin, bool placed) {
  if (mannequin < 0 || mannequin >= mannequinCount())
    throw std::invalid_argument("collision: no mannequin " + std::to_string(mannequin));
  impl_->mannequins[static_cast<std::size_t>(mannequin)].placed = placed;
}
bool CollisionWorld::mannequinPlaced(int mannequin) const {
  if (mannequin < 0 || mannequin >= mannequinCount())
    throw std::invalid_argument("collision: no mannequin " + std::to_string(mannequin));
  return impl_->mannequins[static_cast<std::size_t>(mannequin)].placed;
}

int CollisionWorld::bodyCount() const { return static_cast<int>(impl_->bodies.size()); }
const std::string& CollisionWorld::bodyName(int body) const {
  impl_->checkBody(body);
  return impl_->bodies[body].name;
}
int CollisionWorld::findBody(const std::string& name) const {
  const auto it = impl_->by_name.find(name);
  return it == impl_->by_name.end() ? -1 : it->second;
}
BodyKind CollisionWorld::bodyKind(int body) const {
  impl_->checkBody(body);
  return impl_->bodies[body].kind;
}
const SE3& CollisionWorld::bodyPose(int body) const {
  impl_->checkBody(body);
  return impl_->bodies[body].oMb;
}
double CollisionWorld::margin(int body) const {
  impl_->checkBody(body);
  return impl_->bodies[body].margin;
}
int CollisionWorld::segmentBody(int mannequin, int segment) const {
  const auto& ms = impl_->mannequins;
  if (mannequin < 0 || mannequin >= static_cast<int>(ms.size())) return -1;
  const auto& sb = ms[mannequin].segment_body;
  return segment >= 0 && segment < static_cast<int>(sb.size()) ? sb[segment] : -1;
}
int CollisionWorld::mannequinCount() const { return static_cast<int>(impl_->mannequins.size()); }
bool CollisionWorld::pairEnabled(int a, int b) const {
  impl_->checkBody(a);
  impl_->checkBody(b);
  return impl_->pairEnabled(a, b);
}
double CollisionWorld::activationDistance() const { return impl_->options.activation_distance; }
void CollisionWorld::setActivationDistance(double distance) {
  if (!std::isfinite(distance) || distance < 0.0)
    throw std::invalid_argument("activation distance must be finite and >= 0");
  impl_->options.activation_distance = distance;
  impl_->dirty = true;
}

}  // namespace mannequin::collision
