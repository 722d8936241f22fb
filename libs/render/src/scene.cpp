#include "mannequin/render/scene.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "mannequin/math/frame.hpp"
#include "mannequin/v1/world.pb.h"

namespace mannequin::render {

namespace {

Vector3 toVec(const v1::Vec3& v) { return {v.x(), v.y(), v.z()}; }

SE3 toPose(const v1::Pose& p) {
  SE3 out;
  out.p = toVec(p.position());
  if (p.has_orientation()) {
    Eigen::Quaterniond q(p.orientation().w(), p.orientation().x(), p.orientation().y(), p.orientation().z());
    if (q.norm() > 1e-12) out.R = q.normalized().toRotationMatrix();
  }
  return out;
}

/// A capsule (or a sphere when the ends coincide) between world points a and b.
Primitive capsuleBetween(const Vector3& a, const Vector3& b, double radius) {
  Primitive p;
  const Vector3 d = b - a;
  const double len = d.norm();
  p.radius = radius;
  if (len < 1e-9) {
    p.kind = Kind::kSphere;
    p.pose.p = a;
    return p;
  }
  p.kind = Kind::kCapsule;
  p.pose = SE3(math::frameAlong(d), 0.5 * (a + b));
  p.length = len;
  return p;
}

void appendBody(const collision::BodySpec& body, const SE3& body_pose, Layer layer, const Colour& colour,
                const Colour& plane_colour, const Style& style, std::vector<Primitive>& out) {
  for (const collision::PlacedShape& ps : body.shapes) {
    Primitive p;
    p.layer = layer;
    p.colour = colour;
    p.tag = (layer == Layer::kObject ? "object:" : "scene:") + body.name;
    p.pose = body_pose * ps.pose;
    const collision::Shape& s = ps.shape;
    switch (s.type) {
      case collision::ShapeType::kSphere: p.kind = Kind::kSphere; p.radius = s.radius; break;
      case collision::ShapeType::kCapsule: p.kind = Kind::kCapsule; p.radius = s.radius; p.length = s.length; break;
      case collision::ShapeType::kCylinder: p.kind = Kind::kCylinder; p.radius = s.radius; p.length = s.length; break;
      case collision::ShapeType::kBox: p.kind = Kind::kBox; p.size = s.size; break;
      case collision::ShapeType::kMesh: p.kind = Kind::kMesh; p.mesh = s.mesh; break;
      case collision::ShapeType::kPlane: {
        // world normal and offset of the surface n·x = offset
        p.kind = Kind::kPlane;
        p.normal = (p.pose.R * s.normal).normalized();
        p.offset = s.offset + p.normal.dot(p.pose.p);
        p.length = style.plane_extent;
        p.colour = plane_colour;
        p.pose = SE3(math::frameAlong(p.normal), p.normal * p.offset);
        break;
      }
    }
    out.push_back(std::move(p));
  }
}

}  // namespace

void SceneAssets::addModel(const std::string& key, const skeleton::Model& model) {
  auto& table = capsules[key];
  table.clear();
  for (const skeleton::Segment& s : model.segments) table[s.name] = s.capsule;
}

std::size_t RenderScene::count(Layer layer) const {
  return static_cast<std::size_t>(
      std::count_if(solids.begin(), solids.end(), [&](const Primitive& p) { return p.layer == layer; }));
}

std::size_t RenderScene::countTagged(const std::string& prefix) const {
  return static_cast<std::size_t>(std::count_if(
      solids.begin(), solids.end(), [&](const Primitive& p) { return p.tag.rfind(prefix, 0) == 0; }));
}

const std::array<const char*, RenderLayers::kCount>& RenderLayers::names() {
  static const std::array<const char*, kCount> n{"mannequins", "scene", "objects", "contacts", "balance",
                                                 "control_frames", "overlay"};
  return n;
}

bool& RenderLayers::flag(int i) {
  switch (i) {
    case 0: return mannequins;
    case 1: return scene;
    case 2: return objects;
    case 3: return contacts;
    case 4: return balance;
    case 5: return control_frames;
    default: return overlay;
  }
}

bool RenderLayers::shows(Layer layer) const {
  switch (layer) {
    case Layer::kScene: return scene;
    case Layer::kObject: return objects;
    case Layer::kMannequin: return mannequins;
    case Layer::kContact:
    case Layer::kForce: return contacts;
    case Layer::kBalance: return balance;
    case Layer::kControl: return control_frames;
  }
  return true;
}

void applyLayers(RenderScene& scene, const RenderLayers& layers) {
  std::erase_if(scene.solids, [&](const Primitive& p) { return !layers.shows(p.layer); });
  std::erase_if(scene.lines, [&](const Polyline& l) { return !layers.shows(l.layer); });
}

Colour forceColour(double newtons, const Style& style) {
  const double t = style.force_full > 0 ? std::clamp(newtons / style.force_full, 0.0, 1.0) : 1.0;
  // yellow (1, 0.9, 0.1) → red (0.95, 0.1, 0.05)
  return {static_cast<float>(1.0 - 0.05 * t), static_cast<float>(0.9 - 0.8 * t), static_cast<float>(0.1 - 0.05 * t),
          1.0f};
}

void appendArrow(const Vector3& from, const Vector3& vector, double radius, const Colour& colour, Layer layer,
                 const std::string& tag, std::vector<Primitive>& out) {
  const double len = vector.norm();
  if (!(len > 1e-9)) return;
  const Vector3 dir = vector / len;
  const math::Matrix3 R = math::frameAlong(dir);
  const double head = std::min(0.4 * len, 5.0 * radius);
  const double shaft = len - head;
  Primitive s;
  s.kind = Kind::kCylinder;
  s.layer = layer;
  s.colour = colour;
  s.tag = tag;
  s.radius = radius;
  s.length = shaft;
  s.pose = SE3(R, from + 0.5 * shaft * dir);
  if (shaft > 1e-9) out.push_back(s);
  Primitive c = s;
  c.kind = Kind::kCone;
  c.radius = 2.2 * radius;
  c.length = head;
  c.pose = SE3(R, from + shaft * dir);  // cone base at the end of the shaft, apex at from + vector
  out.push_back(std::move(c));
}

RenderScene buildStaticScene(const SceneAssets& assets, const Style& style) {
  RenderScene out;
  for (const collision::BodySpec& b : assets.scene.bodies)
    appendBody(b, b.pose, b.movable ? Layer::kObject : Layer::kScene, b.movable ? style.object_colour : style.scene_colour,
               style.floor_colour, style, out.solids);
  return out;
}

std::vector<std::array<double, 2>> convexHull(std::vector<std::array<double, 2>> pts) {
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  const auto cross = [](const std::array<double, 2>& o, const std::array<double, 2>& a, const std::array<double, 2>& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  std::vector<std::array<double, 2>> h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], pts[i - 1]) <= 0) --k;
    h[k++] = pts[i - 1];
  }
  h.resize(k - 1);
  return h;
}

RenderScene buildScene(const v1::WorldState& state, const SceneAssets& assets, const Style& style) {
  RenderScene out;
  out.step = state.step();
  out.sim_time = state.sim_time();
  out.contacts_stale = state.contacts_stale();

  // static scene; movable bodies at their ObjectState pose
  std::map<std::string, SE3> object_pose;
  for (const v1::ObjectState& o : state.objects()) object_pose[o.name()] = toPose(o.pose());
  for (const collision::BodySpec& b : assets.scene.bodies) {
    SE3 pose = b.pose;
    if (b.movable) {
      if (const auto it = object_pose.find(b.name); it != object_pose.end()) pose = it->second;
    }
    appendBody(b, pose, b.movable ? Layer::kObject : Layer::kScene, b.movable ? style.object_colour : style.scene_colour,
               style.floor_colour, style, out.solids);
  }

  for (int mi = 0; mi < state.mannequins_size(); ++mi) {
    const v1::MannequinState& m = state.mannequins(mi);
    const Colour colour = style.mannequin_colours.empty()
                              ? Colour{0.2f, 0.45f, 0.95f, 1.0f}
                              : style.mannequin_colours[static_cast<std::size_t>(mi) % style.mannequin_colours.size()];
    const std::map<std::string, skeleton::Capsule>* table = nullptr;
    if (auto it = assets.capsules.find(m.name()); it != assets.capsules.end()) table = &it->second;
    else if (auto it2 = assets.capsules.find(m.model()); it2 != assets.capsules.end()) table = &it2->second;
    for (const v1::NamedPose& seg : m.segments()) {
      const SE3 pose = toPose(seg.pose());
      Primitive p;
      const skeleton::Capsule* cap = nullptr;
      if (table) {
        if (auto c = table->find(seg.name()); c != table->end()) cap = &c->second;
      }
      if (cap && cap->radius > 0) {
        p = capsuleBetween(pose.act(cap->a), pose.act(cap->b), cap->radius);
      } else {
        p.kind = Kind::kSphere;
        p.radius = style.fallback_segment_radius;
        p.pose.p = pose.p;
      }
      p.layer = Layer::kMannequin;
      p.colour = colour;
      p.tag = "mannequin:" + m.name() + "/" + seg.name();
      out.solids.push_back(std::move(p));
    }

    // contacts and force arrows; foot contacts on the floor span the support polygon
    std::vector<std::array<double, 2>> support;
    for (const v1::ContactPoint& c : m.contacts()) {
      const Vector3 point = c.has_point() ? toVec(c.point()) : 0.5 * (toVec(c.point_a()) + toVec(c.point_b()));
      Primitive s;
      s.kind = Kind::kSphere;
      s.layer = Layer::kContact;
      s.radius = style.contact_radius;
      s.pose.p = point;
      s.colour = style.contact_colour;
      s.tag = "contact:" + c.body_a() + ":" + c.body_b();
      out.solids.push_back(std::move(s));
      // ContactPoint.force is the force on body_a; draw the one on the mannequin (physics contacts have the
      // scene body as a: "scene/floor" → "operator/foot_l", the force on the floor points into it)
      const std::string prefix = m.name() + "/";
      const bool mannequin_is_b = c.body_a().rfind(prefix, 0) != 0 && c.body_b().rfind(prefix, 0) == 0;
      const Vector3 f = mannequin_is_b ? Vector3(-toVec(c.force())) : toVec(c.force());
      const double fn = f.norm();
      if (fn > style.force_threshold) {
        const double len = std::clamp(style.force_scale * fn, style.force_min_length, style.force_max_length);
        appendArrow(point, f / fn * len, style.arrow_radius, forceColour(fn, style), Layer::kForce,
                    "force:" + c.body_a() + ":" + c.body_b(), out.solids);
      }
      const bool pressing = fn > style.force_threshold || c.normal_force() > 0;
      if (pressing && std::abs(c.normal().z()) > 0.7 && point.z() < style.support_height)
        support.push_back({point.x(), point.y()});
    }
    if (m.has_com()) {
      Primitive s;
      s.kind = Kind::kSphere;
      s.layer = Layer::kBalance;
      s.radius = style.com_radius;
      s.pose.p = toVec(m.com());
      s.colour = style.com_colour;
      s.tag = "com:" + m.name();
      out.solids.push_back(std::move(s));
    }
    // control frames: achieved pose (shaded axes), target (unlit axes lines), error line between them
    for (const v1::ControlFrameState& cf : m.control_frames()) {
      const std::string tag = "control:" + m.name() + "/" + cf.frame();
      const bool has_actual = cf.has_actual(), has_target = cf.has_target();
      const SE3 actual = toPose(cf.actual()), target = toPose(cf.target());
      const double L = style.control_axis_length;
      if (has_actual) {
        for (int a = 0; a < 3; ++a) {
          Primitive c;
          c.kind = Kind::kCylinder;
          c.layer = Layer::kControl;
          c.radius = style.control_axis_radius;
          c.length = L;
          const Vector3 axis = actual.R.col(a);
          c.pose = SE3(math::frameAlong(axis), actual.p + 0.5 * L * axis);
          c.colour = style.control_axis_colours[static_cast<std::size_t>(a)];
          c.tag = tag;
          out.solids.push_back(std::move(c));
        }
      }
      if (has_target) {
        for (int a = 0; a < 3; ++a) {
          Polyline l;
          l.layer = Layer::kControl;
          l.colour = cf.tracked() ? style.control_target_colours[static_cast<std::size_t>(a)] : style.control_untracked_colour;
          l.points = {target.p, target.p + L * target.R.col(a)};
          out.lines.push_back(std::move(l));
        }
      }
      if (has_actual && has_target && (target.p - actual.p).norm() > style.control_error_min) {
        Polyline l;
        l.layer = Layer::kControl;
        l.colour = style.control_error_colour;
        l.points = {actual.p, target.p};
        out.lines.push_back(std::move(l));
      }
    }
    const auto hull = convexHull(std::move(support));
    if (hull.size() >= 2) {
      Polyline l;
      l.closed = hull.size() >= 3;
      l.colour = style.support_colour;
      for (const auto& h : hull) l.points.emplace_back(h[0], h[1], 0.004);
      out.lines.push_back(std::move(l));
    }
  }
  return out;
}

}  // namespace mannequin::render
