#include "mannequin/render/view.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Geometry>

#include "mannequin/core/config.hpp"
#include "mannequin/v1/mocap.pb.h"
#include "mannequin/v1/world.pb.h"

namespace mannequin::render {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

ViewConfig fromNode(const core::ConfigNode& root) {
  ViewConfig v;
  v.source = root.file();
  root.allowOnly({"name", "type", "size", "background", "camera", "wall", "head", "head_body", "head_offset", "near",
                  "far", "style", "sync", "sync_timeout", "layers", "follow", "stereo"});
  if (auto y = root.find("sync")) v.sync = y->boolean();
  v.sync_timeout = root.getIn("sync_timeout", v.sync_timeout, 0.01, 60.0);
  v.name = root.get("name", v.name);
  if (!root.has("type")) root.fail("missing key 'type' (desktop or wall)");
  v.type = root["type"].choice({"desktop", "wall"}) == 0 ? ViewConfig::Type::kDesktop : ViewConfig::Type::kWall;
  if (auto s = root.find("size")) {
    const Eigen::VectorXd sz = s->vector(2);
    if (sz[0] < 1 || sz[1] < 1 || sz[0] > 16384 || sz[1] > 16384 || sz[0] != std::floor(sz[0]) || sz[1] != std::floor(sz[1]))
      s->fail("expected [width, height], whole pixels in [1, 16384]");
    v.width = static_cast<int>(sz[0]);
    v.height = static_cast<int>(sz[1]);
  }
  if (auto b = root.find("background")) {
    const Eigen::Vector3d c = b->vec3();
    for (int i = 0; i < 3; ++i) {
      if (c[i] < 0 || c[i] > 1) b->fail("expected [r, g, b] in [0, 1]");
      v.background[static_cast<std::size_t>(i)] = static_cast<float>(c[i]);
    }
  }
  if (auto s = root.find("style")) {
    s->allowOnly({"force_scale", "force_full"});
    if (auto f = s->find("force_scale")) v.style.force_scale = f->positive();
    if (auto f = s->find("force_full")) v.style.force_full = f->positive();
  }
  if (auto l = root.find("layers")) {
    if (!l->isMap()) l->fail("expected a map {layer: true|false}");
    const auto& names = RenderLayers::names();
    l->allowOnly(std::vector<std::string>(names.begin(), names.end()));
    for (int i = 0; i < RenderLayers::kCount; ++i)
      if (auto f = l->find(names[static_cast<std::size_t>(i)])) v.layers.flag(i) = f->boolean();
  }
  if (auto f = root.find("follow")) {
    if (v.type != ViewConfig::Type::kDesktop) f->fail("only a desktop view follows a mannequin (type: desktop)");
    v.follow = f->str();
    if (v.follow.empty()) f->fail("expected a mannequin name or index");
  }
  if (auto st = root.find("stereo")) {
    if (v.type != ViewConfig::Type::kWall) st->fail("only a wall view has stereo (type: wall)");
    st->allowOnly({"eye_separation", "mode"});
    v.stereo.enabled = true;
    if (auto e = st->find("eye_separation")) {
      v.stereo.eye_separation = e->positive();
      if (v.stereo.eye_separation > 0.5) e->fail("expected metres between the eyes, in (0, 0.5]");
    }
    if (auto m = st->find("mode")) (void)m->choice({"side_by_side"});
  }
  if (v.type == ViewConfig::Type::kDesktop) {
    for (const char* k : {"wall", "head", "head_body", "head_offset", "near", "far"})
      if (root.has(k)) root[k].fail("only a wall view has this key (type: wall)");
    if (auto c = root.find("camera")) {
      c->allowOnly({"target", "distance", "yaw_deg", "pitch_deg", "fov_y_deg", "near", "far"});
      if (auto t = c->find("target")) v.orbit.target = t->vec3();
      if (auto t = c->find("distance")) v.orbit.distance = t->positive();
      if (auto t = c->find("yaw_deg")) v.orbit.yaw = t->num() * kDeg;
      if (auto t = c->find("pitch_deg")) v.orbit.pitch = t->numIn(-89, 89) * kDeg;
      if (auto t = c->find("fov_y_deg")) v.orbit.fov_y = t->numIn(1, 170) * kDeg;
      if (auto t = c->find("near")) v.orbit.near_plane = t->positive();
      if (auto t = c->find("far")) v.orbit.far_plane = t->positive();
      if (v.orbit.far_plane <= v.orbit.near_plane) (*c)["far"].fail("far must be greater than near");
    }
  } else {
    if (root.has("camera")) root["camera"].fail("a wall view has no orbit camera (keys: wall, head, near, far)");
    if (!root.has("wall")) root.fail("missing key 'wall' ({lower_left, lower_right, upper_left})");
    const core::ConfigNode w = root["wall"];
    w.allowOnly({"lower_left", "lower_right", "upper_left"});
    v.wall.lower_left = w["lower_left"].vec3();
    v.wall.lower_right = w["lower_right"].vec3();
    v.wall.upper_left = w["upper_left"].vec3();
    if (auto h = root.find("head")) v.head = h->vec3();
    if (auto h = root.find("head_body")) {
      v.head_body = h->str();
      if (v.head_body.empty()) h->fail("expected a rigid body name of mocap.frame");
    }
    if (auto h = root.find("head_offset")) v.head_offset = h->vec3();
    if (auto t = root.find("near")) v.near_plane = t->positive();
    if (auto t = root.find("far")) v.far_plane = t->positive();
    if (v.far_plane <= v.near_plane) root["far"].fail("far must be greater than near");
    try {
      (void)v.eyes(2, 1);  // the head's camera, or both eyes'
    } catch (const std::invalid_argument& e) {
      w.fail(e.what());
    }
  }
  return v;
}
}  // namespace

Camera ViewConfig::camera(int image_width, int image_height) const {
  if (type == Type::kWall) return wallCamera(wall, head, near_plane, far_plane);
  return orbit.camera(static_cast<double>(image_width) / std::max(1, image_height));
}

std::vector<EyeView> ViewConfig::eyes(int image_width, int image_height) const {
  if (type != Type::kWall || !stereo.enabled) return {EyeView{camera(image_width, image_height), 0, image_width}};
  const Vec3 vr = (wall.lower_right - wall.lower_left).normalized();
  const Vec3 half = 0.5 * stereo.eye_separation * vr;
  const int left = image_width / 2;
  return {EyeView{wallCamera(wall, head - half, near_plane, far_plane), 0, left},
          EyeView{wallCamera(wall, head + half, near_plane, far_plane), left, image_width - left}};
}

std::optional<Vec3> trackedHead(const v1::MocapFrame& frame, const ViewConfig& view) {
  if (view.head_body.empty()) return std::nullopt;
  for (const v1::RigidBody& b : frame.bodies()) {
    if (b.name() != view.head_body || !b.tracked()) continue;
    const auto& p = b.pose().position();
    const auto& o = b.pose().orientation();
    Eigen::Quaterniond q(o.w(), o.x(), o.y(), o.z());
    if (!(q.norm() > 1e-9)) q = Eigen::Quaterniond::Identity();
    const Vec3 eye = Vec3(p.x(), p.y(), p.z()) + q.normalized() * view.head_offset;
    if (!eye.allFinite()) return std::nullopt;
    return eye;
  }
  return std::nullopt;
}

std::optional<Vec3> followPoint(const v1::WorldState& state, const std::string& follow) {
  if (follow.empty()) return std::nullopt;
  const v1::MannequinState* m = nullptr;
  for (const v1::MannequinState& c : state.mannequins())
    if (c.name() == follow) {
      m = &c;
      break;
    }
  if (m == nullptr && std::all_of(follow.begin(), follow.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
      follow.size() < 9) {
    const int i = std::stoi(follow);
    if (i < state.mannequins_size()) m = &state.mannequins(i);
  }
  if (m == nullptr) return std::nullopt;
  const auto vec = [](const v1::Vec3& p) { return Vec3(p.x(), p.y(), p.z()); };
  for (const v1::NamedPose& s : m->segments())
    if (s.name() == "pelvis") return vec(s.pose().position());
  if (m->segments_size() > 0) return vec(m->segments(0).pose().position());
  if (m->has_com()) return vec(m->com());
  return std::nullopt;
}

OrbitCamera followed(const OrbitCamera& orbit, const v1::WorldState& state, const std::string& follow,
                     const Eigen::Vector2d& offset) {
  OrbitCamera out = orbit;
  const auto p = followPoint(state, follow);
  if (p && p->allFinite()) {
    out.target.x() = p->x() + offset.x();
    out.target.y() = p->y() + offset.y();
  }
  return out;
}

ViewConfig parseView(const std::string& yaml_text, const std::string& source) {
  return fromNode(core::ConfigNode::parse(yaml_text, source));
}

ViewConfig loadView(const std::string& path) { return fromNode(core::ConfigNode::load(path)); }

std::array<int, 2> parseSize(const std::string& text) {
  const auto x = text.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument("");
    std::size_t n1 = 0, n2 = 0;
    const int w = std::stoi(text.substr(0, x), &n1);
    const int h = std::stoi(text.substr(x + 1), &n2);
    if (n1 != x || n2 != text.size() - x - 1 || w < 1 || h < 1 || w > 16384 || h > 16384) throw std::invalid_argument("");
    return {w, h};
  } catch (const std::exception&) {
    throw std::invalid_argument("size '" + text + "': expected WIDTHxHEIGHT, e.g. 1280x720 (1 to 16384 pixels)");
  }
}

}  // namespace mannequin::render
