#include "mannequin/transport/validate.hpp"

#include <fmt/format.h>

#include <cmath>

#include "mannequin/transport/convert.hpp"

namespace mannequin::transport {

namespace {
bool finite(const v1::Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }
}  // namespace

std::string validateMocapFrame(const v1::MocapFrame& frame) {
  for (int i = 0; i < frame.bodies_size(); ++i) {
    const v1::RigidBody& b = frame.bodies(i);
    if (b.name().empty()) return fmt::format("body {} has no name", i);
    if (!std::isfinite(b.quality())) return fmt::format("body '{}': quality is not finite", b.name());
    if (!b.tracked()) continue;
    if (!b.has_pose()) return fmt::format("body '{}': tracked without a pose", b.name());
    const std::string why = checkPose(b.pose());
    if (!why.empty()) return fmt::format("body '{}': {}", b.name(), why);
  }
  return {};
}

std::string validateContactSet(const v1::ContactSet& contacts) {
  for (int i = 0; i < contacts.contacts_size(); ++i) {
    const v1::Contact& c = contacts.contacts(i);
    if (!finite(c.point_a()) || !finite(c.point_b()) || !finite(c.normal()) || !std::isfinite(c.distance()))
      return fmt::format("contact {} ({} / {}) is not finite", i, c.body_a(), c.body_b());
  }
  return {};
}

std::string validateTrigger(const v1::Trigger& trigger) {
  const std::string& n = trigger.name();
  if (n.empty()) return "trigger without a name";
  if (n.size() > 128) return fmt::format("trigger name of {} characters (at most 128)", n.size());
  for (const char c : n)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "trigger name with a control character";
  if (trigger.value().size() > 4096) return fmt::format("trigger '{}': value of {} bytes (at most 4096)", n, trigger.value().size());
  return {};
}

std::string validateCollisionQuery(const v1::CollisionQuery& query) {
  for (int i = 0; i < query.bodies_size(); ++i) {
    const std::string why = checkPose(query.bodies(i).pose());
    if (!why.empty()) return fmt::format("body '{}': {}", query.bodies(i).body(), why);
  }
  if (!std::isfinite(query.margin()) || query.margin() < 0) return "margin is not finite and >= 0";
  return {};
}

}  // namespace mannequin::transport
