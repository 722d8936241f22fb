#include "mannequin/render/camera.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace mannequin::render {

Vec3 Camera::ndc(const Vec3& world) const {
  const Eigen::Vector4d c = projection * view * world.homogeneous();
  return c.head<3>() / c.w();
}

Eigen::Vector2d Camera::pixel(const Vec3& world, int width, int height) const {
  const Vec3 n = ndc(world);
  return {(n.x() + 1.0) * 0.5 * width, (1.0 - n.y()) * 0.5 * height};
}

Matrix4 frustum(double l, double r, double b, double t, double n, double f) {
  Matrix4 m = Matrix4::Zero();
  m(0, 0) = 2 * n / (r - l);
  m(0, 2) = (r + l) / (r - l);
  m(1, 1) = 2 * n / (t - b);
  m(1, 2) = (t + b) / (t - b);
  m(2, 2) = -(f + n) / (f - n);
  m(2, 3) = -2 * f * n / (f - n);
  m(3, 2) = -1;
  return m;
}

Matrix4 perspective(double fov_y, double aspect, double n, double f) {
  const double t = n * std::tan(0.5 * fov_y);
  return frustum(-t * aspect, t * aspect, -t, t, n, f);
}

Matrix4 lookAt(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 fwd = (target - eye).normalized();
  const Vec3 right = fwd.cross(up).normalized();
  const Vec3 u = right.cross(fwd);
  Matrix4 m = Matrix4::Identity();
  m.block<1, 3>(0, 0) = right.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -fwd.transpose();
  m(0, 3) = -right.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = fwd.dot(eye);
  return m;
}

Vec3 OrbitCamera::eye() const {
  return target + distance * Vec3(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
}

Camera OrbitCamera::camera(double aspect) const {
  Camera c;
  c.eye = eye();
  c.view = lookAt(c.eye, target, Vec3::UnitZ());
  c.projection = perspective(fov_y, aspect, near_plane, far_plane);
  return c;
}

void OrbitCamera::rotate(double dyaw, double dpitch) {
  yaw += dyaw;
  pitch = std::clamp(pitch + dpitch, -1.55, 1.55);
}

void OrbitCamera::pan(double right, double up) {
  const Vec3 fwd = (target - eye()).normalized();
  const Vec3 r = fwd.cross(Vec3::UnitZ()).normalized();
  const Vec3 u = r.cross(fwd);
  target += right * r + up * u;
}

void OrbitCamera::zoom(double factor) { distance = std::clamp(distance * factor, 0.1, 1000.0); }

namespace {
struct WallBasis {
  Vec3 vr, vu, vn;
};
WallBasis basis(const Wall& w) {
  const Vec3 er = w.lower_right - w.lower_left, eu = w.upper_left - w.lower_left;
  if (!(er.norm() > 1e-9) || !(eu.norm() > 1e-9) || !er.allFinite() || !eu.allFinite())
    throw std::invalid_argument("wall: degenerate corners (zero or non-finite width or height)");
  WallBasis b{er.normalized(), eu.normalized(), Vec3::Zero()};
  if (std::abs(b.vr.dot(b.vu)) > 1e-6)
    throw std::invalid_argument("wall: the edges lower_left→lower_right and lower_left→upper_left are not orthogonal");
  b.vn = b.vr.cross(b.vu).normalized();
  return b;
}
}  // namespace

Eigen::Vector4d wallFrustum(const Wall& wall, const Vec3& head, double n) {
  const WallBasis b = basis(wall);
  const Vec3 va = wall.lower_left - head, vb = wall.lower_right - head, vc = wall.upper_left - head;
  const double d = -b.vn.dot(va);
  if (!(d > 1e-9))
    throw std::invalid_argument("wall: the head is on or behind the screen plane (distance " + std::to_string(d) + " m)");
  return {b.vr.dot(va) * n / d, b.vr.dot(vb) * n / d, b.vu.dot(va) * n / d, b.vu.dot(vc) * n / d};
}

Camera wallCamera(const Wall& wall, const Vec3& head, double near_plane, double far_plane) {
  if (!(near_plane > 0) || !(far_plane > near_plane)) throw std::invalid_argument("wall: need 0 < near < far");
  const WallBasis b = basis(wall);
  const Eigen::Vector4d f = wallFrustum(wall, head, near_plane);
  Camera c;
  c.eye = head;
  c.projection = frustum(f[0], f[1], f[2], f[3], near_plane, far_plane);
  Matrix4 rot = Matrix4::Identity();
  rot.block<1, 3>(0, 0) = b.vr.transpose();
  rot.block<1, 3>(1, 0) = b.vu.transpose();
  rot.block<1, 3>(2, 0) = b.vn.transpose();
  Matrix4 tr = Matrix4::Identity();
  tr.block<3, 1>(0, 3) = -head;
  c.view = rot * tr;
  return c;
}

}  // namespace mannequin::render
