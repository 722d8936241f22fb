#pragma once
/// \file camera.hpp
/// \brief Cameras: the desktop orbit camera and the VR-wall off-axis (asymmetric) frustum.
///
/// Conventions (OpenGL's): the VIEW matrix maps world points to eye coordinates (x right, y up, the
/// camera looking along −z); the PROJECTION maps eye coordinates to clip space, NDC in [−1, 1]³
/// (x right, y up, depth −1 at the near plane). World: the simulation's frame, z up, metres.
/// Window pixels: column = (x_ndc + 1)/2 · width, row from the TOP = (1 − y_ndc)/2 · height.
///
/// Wall (a CAVE side or powerwall, Kooima 2008, "Generalized Perspective Projection"): the screen is a
/// rectangle given by three corners in room (= world) coordinates, lower-left pa, lower-right pb and
/// upper-left pc, seen from the head (eye) position pe. With the screen basis vr = (pb−pa)/|pb−pa|,
/// vu = (pc−pa)/|pc−pa|, vn = vr × vu (towards the viewer) and d = −vn·(pa−pe) (eye-to-screen distance),
/// the frustum at the near plane n is l = vr·(pa−pe) n/d, r = vr·(pb−pe) n/d, b = vu·(pa−pe) n/d,
/// t = vu·(pc−pe) n/d; projection = frustum(l, r, b, t, n, f), view = Mᵀ T(−pe) with M = [vr vu vn].
/// So a world point on the screen rectangle lands on the pixel at that place of the physical screen,
/// whatever the head position: adjacent walls agree along their shared edge.
#include <Eigen/Core>

namespace mannequin::render {

using Matrix4 = Eigen::Matrix4d;
using Vec3 = Eigen::Vector3d;

/// A camera as the renderer uses it.
struct Camera {
  Matrix4 view = Matrix4::Identity();
  Matrix4 projection = Matrix4::Identity();
  Vec3 eye = Vec3::Zero();  ///< world position (lighting)

  /// NDC (x, y, z) of a world point (perspective divide done). w ≤ 0 (behind the eye) gives non-finite.
  Vec3 ndc(const Vec3& world) const;
  /// Pixel (column from the left, row from the top, continuous) of a world point in a width × height image.
  Eigen::Vector2d pixel(const Vec3& world, int width, int height) const;
};

/// glFrustum's matrix.
Matrix4 frustum(double l, double r, double b, double t, double n, double f);
/// gluPerspective's matrix: vertical field of view (rad), aspect = width/height.
Matrix4 perspective(double fov_y, double aspect, double n, double f);
/// gluLookAt's view matrix. \pre eye ≠ target, up not parallel to target − eye.
Matrix4 lookAt(const Vec3& eye, const Vec3& target, const Vec3& up);

/// Desktop camera orbiting a target point, z up.
struct OrbitCamera {
  Vec3 target{0.0, 0.0, 1.0};
  double distance = 3.5;   ///< m
  double yaw = 0.0;        ///< rad, about world z; 0: the eye on the +x side of the target looking along −x
  double pitch = 0.3;      ///< rad, elevation of the eye above the target's horizontal plane (|pitch| < π/2)
  double fov_y = 0.785398163397448;  ///< rad (45°)
  double near_plane = 0.05, far_plane = 100.0;

  Vec3 eye() const;
  Camera camera(double aspect) const;
  /// Mouse interaction: rotate (rad), pan (in the view plane, m), zoom (distance factor).
  void rotate(double dyaw, double dpitch);
  void pan(double right, double up);
  void zoom(double factor);
};

/// A VR wall: the screen rectangle in room coordinates (see the file comment).
struct Wall {
  Vec3 lower_left, lower_right, upper_left;  ///< pa, pb, pc (m); the edges pa→pb and pa→pc must be orthogonal
};

/// The off-axis camera of a wall seen from `head` (Kooima). \throws std::invalid_argument on a degenerate
/// or non-rectangular wall (edges not orthogonal within 1e-6 rad), or a head on or behind the screen plane.
Camera wallCamera(const Wall& wall, const Vec3& head, double near_plane, double far_plane);

/// The frustum bounds (l, r, b, t) at the near plane of wallCamera (for tests and docs).
Eigen::Vector4d wallFrustum(const Wall& wall, const Vec3& head, double near_plane);

}  // namespace mannequin::render
