#include "mannequin/collision/geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace mannequin::collision;

TEST(Geometry, SegmentSegmentCrossingAndParallel) {
  double s, t;
  Vector3 cp, cq;
  // skew perpendicular segments 0.3 apart
  double d = closestSegmentSegment(Vector3(-1, 0, 0), Vector3(1, 0, 0), Vector3(0.2, -1, 0.3),
                                   Vector3(0.2, 1, 0.3), s, t, cp, cq);
  EXPECT_NEAR(d, 0.3, 1e-14);
  EXPECT_NEAR(s, 0.6, 1e-14);
  EXPECT_NEAR(t, 0.5, 1e-14);
  EXPECT_TRUE(cp.isApprox(Vector3(0.2, 0, 0)));
  // end-to-end: closest are the ends
  d = closestSegmentSegment(Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(2, 1, 0), Vector3(3, 1, 0), s, t, cp, cq);
  EXPECT_NEAR(d, std::sqrt(2.0), 1e-14);
  EXPECT_EQ(s, 1.0);
  EXPECT_EQ(t, 0.0);
  // parallel overlapping, 0.5 apart
  d = closestSegmentSegment(Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(0.5, 0, 0.5), Vector3(2, 0, 0.5), s, t, cp, cq);
  EXPECT_NEAR(d, 0.5, 1e-14);
  // degenerate: a point and a segment
  d = closestSegmentSegment(Vector3(0.5, 2, 0), Vector3(0.5, 2, 0), Vector3(0, 0, 0), Vector3(1, 0, 0), s, t, cp, cq);
  EXPECT_NEAR(d, 2.0, 1e-14);
  EXPECT_NEAR(t, 0.5, 1e-14);
}

TEST(Geometry, PointTriangleRegions) {
  const Vector3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_TRUE(closestPointTriangle(Vector3(0.2, 0.2, 3), a, b, c).isApprox(Vector3(0.2, 0.2, 0)));
  EXPECT_TRUE(closestPointTriangle(Vector3(-1, -1, 1), a, b, c).isApprox(a));
  EXPECT_TRUE(closestPointTriangle(Vector3(2, -1, 0), a, b, c).isApprox(b));
  EXPECT_TRUE(closestPointTriangle(Vector3(0.5, -2, 0), a, b, c).isApprox(Vector3(0.5, 0, 0)));
  EXPECT_TRUE(closestPointTriangle(Vector3(1, 1, 0), a, b, c).isApprox(Vector3(0.5, 0.5, 0)));
}

TEST(Geometry, SegmentTriangleCrossingAndAbove) {
  const Vector3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  Vector3 cs, ct;
  EXPECT_EQ(closestSegmentTriangle(Vector3(0.2, 0.2, -1), Vector3(0.2, 0.2, 1), a, b, c, cs, ct), 0.0);
  EXPECT_TRUE(cs.isApprox(Vector3(0.2, 0.2, 0)));
  // lying above, parallel: distance 0.4
  EXPECT_NEAR(closestSegmentTriangle(Vector3(0.1, 0.1, 0.4), Vector3(0.3, 0.1, 0.4), a, b, c, cs, ct), 0.4, 1e-14);
  // beside the hypotenuse, in the plane
  EXPECT_NEAR(closestSegmentTriangle(Vector3(1, 1, 0), Vector3(2, 2, 0), a, b, c, cs, ct), std::sqrt(0.5), 1e-14);
}

TEST(Geometry, BoxSignedDistanceInsideOutside) {
  const Vector3 half(0.5, 0.25, 0.1);
  Vector3 s, n;
  EXPECT_NEAR(signedDistanceBox(Vector3(0, 0, 0.3), half, s, n), 0.2, 1e-15);
  EXPECT_TRUE(n.isApprox(Vector3::UnitZ()));
  EXPECT_NEAR(signedDistanceBox(Vector3(0.8, 0.65, 0.1), half, s, n), 0.5, 1e-15);  // edge: (0.3, 0.4)
  EXPECT_TRUE(s.isApprox(Vector3(0.5, 0.25, 0.1)));
  EXPECT_NEAR(signedDistanceBox(Vector3(0.45, 0, 0), half, s, n), -0.05, 1e-15);  // nearest face x
  EXPECT_TRUE(n.isApprox(Vector3::UnitX()));
}

TEST(Geometry, SegmentBoxAgainstSampling) {
  std::mt19937 g(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const Vector3 half(0.4, 0.3, 0.2);
  for (int trial = 0; trial < 200; ++trial) {
    const Vector3 p0(u(g), u(g), u(g)), p1(u(g), u(g), u(g));
    Vector3 s, surf, n;
    const double d = closestSegmentBox(p0, p1, half, s, surf, n);
    double best = 1e9;
    for (int k = 0; k <= 20000; ++k) {
      Vector3 ss, nn;
      best = std::min(best, signedDistanceBox(p0 + (k / 20000.0) * (p1 - p0), half, ss, nn));
    }
    EXPECT_LE(d, best + 1e-12);
    EXPECT_NEAR(d, best, 1e-4);
  }
}
