// Coplanar balance (thesis 3.3.2.1, 3.22–3.37): the support polygon and ellipse, the signed distances
// of a CoM to them checked by hand, the ellipse fit on simple supports, and the balance row's
// Jacobian (3.37) against finite differences on the male_50th mannequin.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "mannequin/constraints/balance.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "../common/alloc_counter.hpp"
#include "../common/mannequins.hpp"

using namespace mannequin;
using namespace mannequin::constraints;
using Eigen::Vector2d;

namespace {
using mannequin::testing::male50;

/// A 0.4 m square centred at (1, 2) on the floor z = 0, with interior and mid-edge points that the
/// hull must drop.
std::vector<Vector3> square() {
  return {{0.8, 1.8, 0.0}, {1.2, 1.8, 0.0}, {1.2, 2.2, 0.0}, {0.8, 2.2, 0.0},
          {1.0, 2.0, 0.0}, {1.2, 2.0, 0.0}, {1.1, 1.9, 0.0}, {0.8, 1.8, 0.0}};
}

/// The four sole corners of each foot (half length 0.5·foot about the sole frame, half width 0.045 m).
std::vector<Vector3> soleCorners(const skeleton::Model& model, const skeleton::Data& data) {
  std::vector<Vector3> pts;
  const int foot = model.segmentIndex("foot_l");
  const double half = 0.5 * model.segments[static_cast<std::size_t>(foot)].length;
  for (const char* name : {"sole_l", "sole_r"}) {
    const math::SE3& oMs = data.oMf[static_cast<std::size_t>(model.frameIndex(name))];
    for (double sx : {-1.0, 1.0})
      for (double sy : {-1.0, 1.0}) pts.push_back(oMs.act(Vector3(sx * half, sy * 0.045, 0.0)));
  }
  return pts;
}
}  // namespace

TEST(SupportRegion, SquareHullAndHandCheckedDistances) {
  SupportRegion s;
  ASSERT_TRUE(s.setSupport(square()));
  ASSERT_EQ(s.hullSize(), 4);
  EXPECT_NEAR(s.area(), 0.16, 1e-12);
  // a square's inertia ellipse is a circle: Q = I, δ = half diagonal
  EXPECT_TRUE(s.centre().isApprox(Vector2d(1.0, 2.0), 1e-12));
  EXPECT_TRUE(s.metric().isApprox(Eigen::Matrix2d::Identity(), 1e-9));
  EXPECT_NEAR(s.delta(), std::sqrt(0.08), 1e-9);

  // CoM above the centre (its height does not matter: Π projects along n)
  BalanceDistance d = s.distance({1.0, 2.0, 0.95});
  EXPECT_NEAR(d.ellipse, 0.08, 1e-9);
  EXPECT_NEAR(d.ellipse_m, 0.08 / (2 * std::sqrt(0.08)), 1e-9);
  EXPECT_NEAR(d.polygon_m, 0.2, 1e-12);
  // on the edge x = 1.2: polygon 0, inside the enclosing circle by 0.08 − 0.04
  d = s.distance({1.2, 2.0, 1.0});
  EXPECT_NEAR(d.polygon_m, 0.0, 1e-12);
  EXPECT_NEAR(d.ellipse, 0.04, 1e-9);
  // off-centre inside: the nearest edge is y = 2.2
  EXPECT_NEAR(s.distance({1.05, 2.15, 1.0}).polygon_m, 0.05, 1e-12);
  // outside in front of an edge, and beyond a corner
  d = s.distance({1.5, 2.0, 1.0});
  EXPECT_NEAR(d.polygon_m, -0.3, 1e-12);
  EXPECT_NEAR(d.ellipse, 0.08 - 0.25, 1e-9);
  EXPECT_LT(d.ellipse_m, 0.0);
  EXPECT_NEAR(s.distance({1.5, 2.5, 1.0}).polygon_m, -std::sqrt(0.18), 1e-12);
  // on the circle through the corners: d = 0
  EXPECT_NEAR(s.distance({1.0 + std::sqrt(0.08), 2.0, 0.0}).ellipse, 0.0, 1e-9);
}

TEST(SupportRegion, RectangleEllipseIsTheMinimumAreaEnclosingOne) {
  // a 0.6 × 0.2 rectangle rotated by 30° about z: Σ = R diag(a²/12, b²/12) Rᵀ, Q = λ_min(Σ) Σ⁻¹
  const double a = 0.6, b = 0.2, th = M_PI / 6;
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(th).toRotationMatrix();
  std::vector<Vector3> pts;
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      const Vector2d p = Vector2d(0.3, -0.1) + R * Vector2d(sx * a / 2, sy * b / 2);
      pts.emplace_back(p.x(), p.y(), 0.0);
    }
  SupportRegion s;
  ASSERT_TRUE(s.setSupport(pts));
  EXPECT_EQ(s.hullSize(), 4);
  EXPECT_TRUE(s.centre().isApprox(Vector2d(0.3, -0.1), 1e-12));
  const Eigen::Matrix2d Q = R * Eigen::Vector2d(b * b / (a * a), 1.0).asDiagonal() * R.transpose();
  EXPECT_TRUE(s.metric().isApprox(Q, 1e-9)) << s.metric();
  // semi-minor axis b/√2 = δ, semi-major a/√2 (Löwner ellipse of a rectangle); every corner on it
  EXPECT_NEAR(s.delta(), b / std::sqrt(2.0), 1e-12);
  for (const Vector3& p : pts) EXPECT_NEAR(s.distance(p).ellipse, 0.0, 1e-12);
  const Vector2d major = Vector2d(0.3, -0.1) + R * Vector2d(a / std::sqrt(2.0), 0);
  EXPECT_NEAR(s.distance({major.x(), major.y(), 0.7}).ellipse, 0.0, 1e-12);

  // the inscribed ellipse: semi-axes a/2, b/2, tangent to the edges
  BalanceOptions o;
  o.inscribed = true;
  SupportRegion in(o);
  ASSERT_TRUE(in.setSupport(pts));
  EXPECT_NEAR(in.delta(), b / 2, 1e-12);
  const Vector2d side = Vector2d(0.3, -0.1) + R * Vector2d(a / 2, 0);
  EXPECT_NEAR(in.distance({side.x(), side.y(), 0.0}).ellipse, 0.0, 1e-12);
  EXPECT_NEAR(in.distance({side.x(), side.y(), 0.0}).polygon_m, 0.0, 1e-12);
}

TEST(SupportRegion, TriangleCentroidEnclosingAndInscribed) {
  const std::vector<Vector3> tri = {{0, 0, 0}, {0.3, 0, 0}, {0, 0.6, 0}};
  SupportRegion s;
  ASSERT_TRUE(s.setSupport(tri));
  EXPECT_NEAR(s.area(), 0.09, 1e-12);
  EXPECT_TRUE(s.centre().isApprox(Vector2d(0.1, 0.2), 1e-12));
  // enclosing: every vertex inside, one on the ellipse
  double worst = 1e9;
  for (const Vector3& p : tri) {
    const double d = s.distance(p).ellipse;
    EXPECT_GE(d, -1e-12);
    worst = std::min(worst, d);
  }
  EXPECT_NEAR(worst, 0.0, 1e-12);
  EXPECT_NEAR(s.metric().eigenvalues().real().maxCoeff(), 1.0, 1e-12);
  // inscribed: the ellipse touches the nearest edge, stays inside the others — sample its boundary
  BalanceOptions o;
  o.inscribed = true;
  SupportRegion in(o);
  ASSERT_TRUE(in.setSupport(tri));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(in.metric());
  double lowest = 1e9;
  for (int k = 0; k < 720; ++k) {
    const double t = 2 * M_PI * k / 720;
    // boundary point: r = δ Q^{-1/2} (cos t, sin t)
    const Vector2d r = in.delta() * eig.operatorInverseSqrt() * Vector2d(std::cos(t), std::sin(t));
    const Vector2d u = in.centre() + r;
    lowest = std::min(lowest, in.polygonDistance(u));
  }
  EXPECT_GE(lowest, -1e-12);
  EXPECT_LT(lowest, 1e-5);  // tangent to an edge (720 samples)
}

TEST(SupportRegion, TiltedFloorProjectsAlongItsNormal) {
  // the square on a floor tilted by 0.3 rad about x: moving the CoM along n changes nothing
  const math::Matrix3 R = math::expSO3(Vector3(0.3, 0, 0));
  SupportRegion s;
  s.setFloor(Vector3(0, 0, 0.5), R * Vector3::UnitZ());
  std::vector<Vector3> pts;
  for (const Vector3& p : square()) pts.push_back(Vector3(0, 0, 0.5) + R * p);
  ASSERT_TRUE(s.setSupport(pts));
  EXPECT_EQ(s.hullSize(), 4);
  const Vector3 com = Vector3(0, 0, 0.5) + R * Vector3(1.5, 2.5, 0.0);
  const BalanceDistance d0 = s.distance(com);
  const BalanceDistance d1 = s.distance(com + 0.8 * s.normal());
  EXPECT_NEAR(d0.polygon_m, -std::sqrt(0.18), 1e-12);
  EXPECT_NEAR(d1.polygon_m, d0.polygon_m, 1e-12);
  EXPECT_NEAR(d1.ellipse, d0.ellipse, 1e-12);
  EXPECT_NEAR(d0.ellipse, 0.08 - 0.5, 1e-9);
}

TEST(SupportRegion, DegenerateEmptyAndBadSupports) {
  SupportRegion s;
  // no support: NaN
  EXPECT_TRUE(s.empty());
  EXPECT_TRUE(std::isnan(s.distance({0, 0, 1}).polygon_m));
  EXPECT_TRUE(std::isnan(s.distance({0, 0, 1}).ellipse));
  // a segment (collinear points): minus the distance to it; its ellipse has δ ≥ min_radius
  ASSERT_TRUE(s.setSupport({{0, 0, 0}, {0.2, 0, 0}, {0.4, 0, 0}}));
  EXPECT_EQ(s.hullSize(), 2);
  EXPECT_NEAR(s.distance({0.1, 0.0, 1}).polygon_m, 0.0, 1e-12);
  EXPECT_NEAR(s.distance({0.1, 0.3, 1}).polygon_m, -0.3, 1e-12);
  EXPECT_NEAR(s.distance({0.7, -0.4, 1}).polygon_m, -0.5, 1e-12);
  EXPECT_GE(s.delta(), s.options().min_radius);
  EXPECT_TRUE(s.centre().isApprox(Vector2d(0.2, 0), 1e-12));
  EXPECT_GT(s.distance({0.2, 0.0, 1}).ellipse, 0.0);
  EXPECT_LT(s.distance({0.2, 0.01, 1}).ellipse, 0.0);  // 10 min_radius across
  // one point (repeated)
  ASSERT_TRUE(s.setSupport({{0.5, 0.5, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 0}}));
  EXPECT_EQ(s.hullSize(), 1);
  EXPECT_NEAR(s.distance({0.8, 0.9, 0}).polygon_m, -0.5, 1e-12);
  // bad input: false and an empty region, no throw
  EXPECT_FALSE(s.setSupport({{0, 0, 0}, {std::nan(""), 0, 0}, {0, 1, 0}}));
  EXPECT_TRUE(s.empty());
  BalanceOptions o;
  o.max_points = 3;
  SupportRegion small(o);
  EXPECT_FALSE(small.setSupport(square()));
  EXPECT_TRUE(small.empty());
  EXPECT_TRUE(small.setSupport({}));
  EXPECT_THROW(s.setFloor(Vector3::Zero(), Vector3::Zero()), std::invalid_argument);
  o.min_radius = 0;
  EXPECT_THROW(SupportRegion{o}, std::invalid_argument);
}

TEST(BalanceRows, ComAndItsJacobianMatchTheSkeletonLibrary) {
  const skeleton::Model& model = male50();
  skeleton::Data data(model), ref(model);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  skeleton::VectorX q = skeleton::standingConfiguration(model);
  for (int k = 0; k < model.nq; ++k) q(k) += u(rng);
  skeleton::computeJointJacobians(model, data, q);
  skeleton::computeJointJacobians(model, ref, q);
  skeleton::jacobianCenterOfMass(model, ref);
  BalanceRows rows(0, model, data);
  EXPECT_FALSE(rows.evaluate());  // no support yet: no row, NaN distances
  EXPECT_TRUE(std::isnan(rows.state().distance.polygon_m));
  EXPECT_TRUE(rows.state().com.isApprox(ref.com, 1e-12));
  EXPECT_TRUE(rows.comJacobian().isApprox(ref.Jcom, 1e-12));
}

TEST(BalanceRows, RowJacobianMatchesFiniteDifferences) {
  const skeleton::Model& model = male50();
  skeleton::Data data(model);
  const skeleton::VectorX q0 = skeleton::standingConfiguration(model);
  skeleton::computeJointJacobians(model, data, q0);
  const std::vector<Vector3> support = soleCorners(model, data);
  BalanceRows rows(0, model, data);
  ASSERT_TRUE(rows.setSupport(support));
  ASSERT_EQ(rows.support().hullSize(), 4);  // the outer corners of the two feet
  ASSERT_TRUE(rows.evaluate());
  EXPECT_GT(rows.state().distance.polygon_m, 0.05);  // standing: the CoM is well inside

  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    // a leaning configuration (CoM inside and outside the support) and a random velocity
    skeleton::VectorX q = q0;
    for (int k = 6; k < model.nq; ++k) q(k) += 0.3 * u(rng);
    q(model.joints[0].idx_q + 4) = 0.25 * u(rng);  // root pitch
    skeleton::VectorX v(model.nv);
    for (int k = 0; k < model.nv; ++k) v(k) = u(rng);
    const auto dm = [&](double eps) {
      skeleton::computeJointJacobians(model, data, skeleton::integrate(model, q, v, eps));
      rows.evaluate();
      return rows.state().distance.ellipse_m;
    };
    const double eps = 1e-6;
    const double fd = (dm(eps) - dm(-eps)) / (2 * eps);
    skeleton::computeJointJacobians(model, data, q);
    ASSERT_TRUE(rows.evaluate());
    const double an = rows.jacobian().dot(v);
    EXPECT_NEAR(an, fd, 1e-6 * (1 + std::abs(fd))) << "trial " << trial << " d_m " << rows.state().distance.ellipse_m;
    // the row is (3.37)/(2δ): compare with the thesis's form on d(q) directly
    const Eigen::Vector2d r = rows.support().project(rows.state().com) - rows.support().centre();
    const Eigen::RowVectorXd thesis = -(r.transpose() * (rows.support().metric() + rows.support().metric().transpose()) *
                                        rows.support().basis().transpose() * rows.comJacobian());
    EXPECT_TRUE((thesis / (2 * rows.support().delta())).isApprox(rows.jacobian(), 1e-12));
  }
}

TEST(BalanceRows, AddsOneUnilateralRowOnlyWithSupport) {
  const skeleton::Model& model = male50();
  skeleton::Data data(model);
  skeleton::computeJointJacobians(model, data, skeleton::standingConfiguration(model));
  // system 1 of two (the other one an object with nv = 6)
  RowSet set({6, model.nv}, 8);
  BalanceRows rows(1, model, data);
  EXPECT_STREQ(rows.name(), "balance");
  rows.addRows(3, 1e-3, set);  // no support: no row, NaN report
  EXPECT_EQ(set.size(), 0);
  EXPECT_EQ(rows.state().row, -1);
  EXPECT_TRUE(std::isnan(rows.state().distance.polygon_m));

  ASSERT_TRUE(rows.setSupport(soleCorners(model, data)));
  rows.addRows(3, 1e-3, set);
  ASSERT_EQ(set.size(), 1);
  const RowInfo& info = set.info(0);
  EXPECT_EQ(info.kind, RowKind::kUnilateral);
  EXPECT_EQ(info.source, RowSource::kBalance);
  EXPECT_EQ(info.producer, 3);
  EXPECT_EQ(info.system_a, 1);
  EXPECT_EQ(info.system_b, -1);
  EXPECT_EQ(info.friction_edges, 0);
  EXPECT_DOUBLE_EQ(info.distance, rows.state().distance.ellipse_m);
  EXPECT_DOUBLE_EQ(info.recovery_speed, rows.support().options().recovery_speed);
  EXPECT_TRUE(set.touches(0, 1));
  EXPECT_FALSE(set.touches(0, 0));
  EXPECT_TRUE(set.jacobians(1).row(0).isApprox(rows.jacobian()));
  EXPECT_TRUE(set.jacobians(0).row(0).isZero());
  // the report: the polygon distance in metres, and λ read back after the solve
  set.info(0).lambda = 12.5;
  rows.solved(3, set);
  EXPECT_DOUBLE_EQ(rows.state().lambda, 12.5);
  // translating the whole body (root at identity: body = world axes) towards the ellipse centre raises d
  const Eigen::Vector2d to_centre = rows.support().centre() - rows.support().project(rows.state().com);
  skeleton::VectorX v = skeleton::VectorX::Zero(model.nv);
  v.segment<3>(3) = rows.support().basis() * to_centre;
  EXPECT_GT(rows.jacobian().dot(v), 0.0);
  EXPECT_LT(rows.jacobian().dot(-v), 0.0);
  EXPECT_THROW(BalanceRows(-1, model, data), std::invalid_argument);
}

TEST(BalanceRows, NoAllocationPerStep) {
  const skeleton::Model& model = male50();
  skeleton::Data data(model);
  skeleton::computeJointJacobians(model, data, skeleton::standingConfiguration(model));
  const std::vector<Vector3> support = soleCorners(model, data);
  RowSet set({model.nv}, 4);
  BalanceRows rows(0, model, data);
  ASSERT_TRUE(rows.setSupport(support));
  rows.addRows(0, 1e-3, set);  // warm-up
  set.clear();
  const long n = countAllocations([&] {
    for (int k = 0; k < 10; ++k) {
      rows.setSupport(support);  // a new support every step
      rows.addRows(0, 1e-3, set);
      rows.solved(0, set);
      set.clear();
    }
  });
  if (n < 0) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  EXPECT_EQ(n, 0);
}
