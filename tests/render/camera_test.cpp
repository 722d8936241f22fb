// Camera math: the orbit camera and the VR wall's off-axis frustum (Kooima's generalized perspective projection).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "mannequin/render/camera.hpp"
#include "mannequin/render/view.hpp"

namespace mannequin::render {
namespace {

// A two-wall corner of a room (world = room, z up), the viewer looking along +x:
// front wall in the plane x = 1.5 (y from +1.2 on the left to −1.2 on the right), right wall in the plane
// y = −1.2 continuing from the front wall's right edge back to x = −0.9. Both 2.4 m high from the floor.
const Wall kFront{{1.5, 1.2, 0.0}, {1.5, -1.2, 0.0}, {1.5, 1.2, 2.4}};
const Wall kRight{{1.5, -1.2, 0.0}, {-0.9, -1.2, 0.0}, {1.5, -1.2, 2.4}};

TEST(WallCamera, HeadCentredInFrontOfTheWallGivesASymmetricFrustum) {
  const Vec3 centre = 0.5 * (kFront.lower_right + kFront.upper_left);  // (1.5, 0, 1.2)
  const Vec3 head = centre - Vec3(1.7, 0, 0);
  const Eigen::Vector4d f = wallFrustum(kFront, head, 0.1);  // l r b t
  EXPECT_NEAR(f[0], -f[1], 1e-12);
  EXPECT_NEAR(f[2], -f[3], 1e-12);
  EXPECT_NEAR(f[1], 1.2 * 0.1 / 1.7, 1e-12);  // half width · n / d
  const Camera c = wallCamera(kFront, head, 0.1, 50);
  const Vec3 n = c.ndc(centre);
  EXPECT_NEAR(n.x(), 0.0, 1e-12);
  EXPECT_NEAR(n.y(), 0.0, 1e-12);
  // an off-centre head gives an asymmetric one
  const Eigen::Vector4d g = wallFrustum(kFront, head + Vec3(0, 0.4, 0.3), 0.1);
  EXPECT_GT(std::abs(g[0] + g[1]), 1e-3);
  EXPECT_GT(std::abs(g[2] + g[3]), 1e-3);
}

TEST(WallCamera, APointOnTheScreenLandsOnItsPlaceOfTheScreenWhateverTheHead) {
  for (const Vec3& head : {Vec3(0, 0, 1.7), Vec3(0.6, -0.5, 1.2), Vec3(-0.8, 0.9, 2.0)}) {
    const Camera c = wallCamera(kFront, head, 0.05, 100);
    for (double s : {0.0, 0.25, 0.5, 1.0})
      for (double t : {0.0, 0.4, 1.0}) {
        const Vec3 p = kFront.lower_left + s * (kFront.lower_right - kFront.lower_left) +
                       t * (kFront.upper_left - kFront.lower_left);
        const Vec3 n = c.ndc(p);
        EXPECT_NEAR(n.x(), 2 * s - 1, 1e-9) << head.transpose();
        EXPECT_NEAR(n.y(), 2 * t - 1, 1e-9) << head.transpose();
      }
  }
}

TEST(WallCamera, AdjacentWallsProjectAPointOnTheirSharedEdgeToTheSameScreenColumn) {
  const Vec3 head(0.3, -0.2, 1.6);  // off-centre: both frusta are asymmetric
  const Camera front = wallCamera(kFront, head, 0.05, 100);
  const Camera right = wallCamera(kRight, head, 0.05, 100);
  const int w = 1280, h = 720;
  for (double z : {0.0, 0.7, 1.3, 2.4}) {
    const Vec3 edge(1.5, -1.2, z);
    for (double k : {1.0, 1.7, 3.0}) {  // on the edge, and behind it along the line of sight
      const Vec3 p = head + k * (edge - head);
      const Eigen::Vector2d pf = front.pixel(p, w, h), pr = right.pixel(p, w, h);
      // the shared physical column: the front wall's right border is the right wall's left border
      EXPECT_NEAR(pf.x(), w, 1e-9) << "z " << z << " k " << k;
      EXPECT_NEAR(pr.x(), 0.0, 1e-9) << "z " << z << " k " << k;
      EXPECT_NEAR(pf.y(), pr.y(), 1e-9) << "z " << z << " k " << k;   // and the same row
      EXPECT_NEAR(pf.y(), (1 - z / 2.4) * h, 1e-9);
    }
  }
  // a point seen through the front wall is inside the front view and outside the right one
  const Vec3 q(3.0, 0.0, 1.0);
  EXPECT_LT(std::abs(front.ndc(q).x()), 1.0);
  EXPECT_GT(std::abs(right.ndc(q).x()), 1.0);
}

TEST(WallCamera, RefusesADegenerateOrSkewedWallAndAHeadBehindIt) {
  EXPECT_THROW(wallCamera({{0, 0, 0}, {0, 0, 0}, {0, 0, 1}}, Vec3(-1, 0, 0), 0.1, 10), std::invalid_argument);
  EXPECT_THROW(wallCamera({{1, 1, 0}, {1, -1, 0}, {1, 0.5, 1}}, Vec3(0, 0, 1), 0.1, 10), std::invalid_argument);
  EXPECT_THROW(wallCamera(kFront, Vec3(2.0, 0, 1), 0.1, 10), std::invalid_argument);  // behind the screen
  EXPECT_THROW(wallCamera(kFront, Vec3(0, 0, 1), 0.1, 0.05), std::invalid_argument);  // far < near
}

TEST(OrbitCamera, TargetAtTheImageCentreAndEyeOnTheYawSide) {
  OrbitCamera o;
  o.target = Vec3(0.4, -0.2, 0.9);
  o.distance = 3.0;
  o.yaw = 0.0;
  o.pitch = 0.0;
  EXPECT_LT((o.eye() - Vec3(3.4, -0.2, 0.9)).norm(), 1e-12);
  const Camera c = o.camera(16.0 / 9.0);
  const Vec3 n = c.ndc(o.target);
  EXPECT_NEAR(n.x(), 0, 1e-12);
  EXPECT_NEAR(n.y(), 0, 1e-12);
  // looking along −x with z up: +y world is to the RIGHT of the image (x out of the screen, y right, z up)
  EXPECT_GT(c.ndc(o.target + Vec3(0, 0.5, 0)).x(), 0.0);
  EXPECT_GT(c.ndc(o.target + Vec3(0, 0, 0.5)).y(), 0.0);
  // the vertical field of view: a point at the top edge of the frustum is at y_ndc = 1
  const Vec3 top = o.target + Vec3(0, 0, o.distance * std::tan(0.5 * o.fov_y));
  EXPECT_NEAR(c.ndc(top).y(), 1.0, 1e-12);
  // interaction keeps the distance and clamps the pitch below the pole
  o.rotate(0.3, 10.0);
  EXPECT_LT(o.pitch, 1.5708);
  EXPECT_NEAR((o.eye() - o.target).norm(), 3.0, 1e-12);
}

TEST(ViewSize, ParsesWidthByHeight) {
  EXPECT_EQ(parseSize("1280x720"), (std::array<int, 2>{1280, 720}));
  for (const char* bad : {"1280", "x720", "1280x", "12a0x720", "0x10", "-5x10", "1280x720x3"})
    EXPECT_THROW(parseSize(bad), std::invalid_argument) << bad;
}

}  // namespace
}  // namespace mannequin::render
