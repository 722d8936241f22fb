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
