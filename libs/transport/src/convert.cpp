#include "mannequin/transport/convert.hpp"

#include <fmt/format.h>

#include <cmath>

namespace mannequin::transport {

void toMsg(const math::Vector3& v, v1::Vec3& out) {
  out.set_x(v.x());
  out.set_y(v.y());
  out.set_z(v.z());
}

void toMsg(const math::SE3& pose, v1::Pose& out) {
  toMsg(pose.p, *out.mutable_position());
  const Eigen::Quaterniond q(pose.R);
  v1::Quat* o = out.mutable_orientation();
  o->set_w(q.w());
  o->set_x(q.x());
  o->set_y(q.y());
  o->set_z(q.z());
}

math::Vector3 fromMsg(const v1::Vec3& v) { return {v.x(), v.y(), v.z()}; }

math::SE3 fromMsg(const v1::Pose& pose) {
  const auto& o = pose.orientation();
  Eigen::Quaterniond q(o.w(), o.x(), o.y(), o.z());
  const double n = q.norm();
  math::SE3 out;
  out.R = n > 1e-12 ? math::Matrix3(Eigen::Quaterniond(q.coeffs() / n).toRotationMatrix()) : math::Matrix3::Identity();
  out.p = fromMsg(pose.position());
  return out;
}

void toMsg(const mocap::Frame& f, const std::string& source_kind, v1::MocapFrame& out) {
  out.Clear();
  out.mutable_header()->set_stamp_ns(f.stamp_ns);
  out.set_frame_number(f.frame_number);
  out.set_calibration_pose(f.calibration_pose);
  out.set_source_kind(source_kind);
  for (const mocap::Body& b : f.bodies) {
    v1::RigidBody* m = out.add_bodies();
    m->set_name(b.name);
    m->set_id(b.id);
    m->set_tracked(b.tracked);
    m->set_quality(b.quality);
    toMsg(b.pose, *m->mutable_pose());
  }
}

mocap::Frame fromMsg(const v1::MocapFrame& msg) {
  mocap::Frame f;
  f.stamp_ns = msg.header().stamp_ns();
  f.sequence = msg.header().sequence();
  f.send_time_ns = msg.header().send_time_ns();
  f.frame_number = msg.frame_number();
  f.calibration_pose = msg.calibration_pose();
  f.bodies.reserve(static_cast<std::size_t>(msg.bodies_size()));
  for (const v1::RigidBody& b : msg.bodies()) {
    mocap::Body& o = f.bodies.emplace_back();
    o.name = b.name();
    o.id = b.id();
    o.tracked = b.tracked();
    o.quality = b.quality();
    o.pose = fromMsg(b.pose());
  }
  return f;
}

std::string checkPose(const v1::Pose& pose, double tolerance) {
  const auto& p = pose.position();
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) return "position is not finite";
  const auto& o = pose.orientation();
  if (!std::isfinite(o.w()) || !std::isfinite(o.x()) || !std::isfinite(o.y()) || !std::isfinite(o.z()))
    return "orientation is not finite";
  const double n = std::sqrt(o.w() * o.w() + o.x() * o.x() + o.y() * o.y() + o.z() * o.z());
  if (std::abs(n - 1.0) > tolerance) return fmt::format("quaternion norm {:.6g} (expected 1)", n);
  return {};
}

}  // namespace mannequin::transport
