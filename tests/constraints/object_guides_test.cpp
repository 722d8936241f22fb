// Guides on objects (sim::GuideRows, thesis 4.1.1 and 4.3.1): an object kept on a virtual mechanism by
// rows of the LCP. Each test steps free motion → solver → integration, like the World.
#include "object_step.hpp"
#include "mannequin/sim/object_guides.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "mannequin/constraints/solver.hpp"

namespace {

using mannequin::math::Matrix3;
using mannequin::math::SE3;
using mannequin::math::Vector3;
using mannequin::math::Vector6;
namespace cs = mannequin::constraints;
namespace sim = mannequin::sim;
namespace ctl = mannequin::control;

using mannequin::testing::kDt;
using mannequin::testing::kGravity;

cs::RigidObjectSpec boxSpec(const SE3& pose, double mass = 2.0) {
  cs::RigidObjectSpec s;
  s.name = "part";
  s.pose = pose;
  s.mass = mass;
  s.inertia = Vector3(0.02, 0.03, 0.04);
  return s;
}

ctl::MechanismSpec mechanism(ctl::MechanismType type, const SE3& base, std::vector<std::pair<double, double>> stops = {}) {
  ctl::MechanismSpec m;
  m.type = type;
  m.base = base;
  if (!stops.empty()) {
    m.lower.resize(static_cast<int>(stops.size()));
    m.upper.resize(static_cast<int>(stops.size()));
    for (std::size_t i = 0; i < stops.size(); ++i) {
      m.lower(static_cast<int>(i)) = stops[i].first;
      m.upper(static_cast<int>(i)) = stops[i].second;
    }
  }
  return m;
}

constexpr double kInf = std::numeric_limits<double>::infinity();

// Every row's Jacobian is the rate of its distance: (d(H exp(hν)) − d(H exp(−hν)))/2h = J ν, for each
// mechanism type, at poses off the manifold (so the rows are not at their zero), random ν.
TEST(ObjectGuide, EveryRowsJacobianIsTheRateOfItsDistance) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const SE3 base(mannequin::math::expSO3(Vector3(0.4, -0.2, 0.3)), Vector3(0.3, 0.1, 1.0));
  for (const ctl::MechanismType type : {ctl::MechanismType::kPrismatic, ctl::MechanismType::kSlidingPivot, ctl::MechanismType::kPlane}) {
    for (int trial = 0; trial < 10; ++trial) {
      // near the base (within the stops' activation), turned and shifted off the manifold
      const SE3 pose = base * SE3(mannequin::math::expSO3(0.2 * Vector3(u(rng), u(rng), u(rng))),
                                  Vector3(0.03 * u(rng), 0.03 * u(rng), 0.02 * u(rng)));
      cs::RigidObject obj(boxSpec(pose));
      sim::GuideRows guides({&obj}, {0}, 0.5);
      const int d = ctl::mechanismDimension(type);
      std::vector<std::pair<double, double>> stops(static_cast<std::size_t>(d), {-0.1, 0.1});
      if (type == ctl::MechanismType::kPlane) stops[3] = {0.0, 0.0};  // n locked: a bilateral stop row
      guides.attach(0, mechanism(type, base, stops));
      Vector6 nu;
      for (int i = 0; i < 6; ++i) nu[i] = u(rng);
      const auto rowsAt = [&](const SE3& H, std::map<int, std::pair<double, double>>& out) {
        obj.setPose(H);
        cs::RowSet rows({6}, 64);
        guides.addRows(0, kDt, rows);
        for (int r = 0; r < rows.size(); ++r) out[rows.info(r).tag] = {rows.info(r).distance, rows.jacobians(0).row(r).dot(nu)};
      };
      std::map<int, std::pair<double, double>> at, plus, minus;
      const double h = 1e-6;
      rowsAt(pose, at);
      rowsAt(pose * mannequin::math::expSE3(h * nu), plus);
      rowsAt(pose * mannequin::math::expSE3(-h * nu), minus);
      ASSERT_GE(at.size(), 4u);
      for (const auto& [tag, dj] : at) {
        ASSERT_TRUE(plus.count(tag) && minus.count(tag)) << "tag " << tag;
        const double fd = (plus[tag].first - minus[tag].first) / (2 * h);
        const int kind = tag % 16;
        // the stop rows of θ use z_bᵀω, exact only with the axes aligned: within the tilt (≤ 0.35 rad) there
        const double tol = (kind >= 8 && type != ctl::MechanismType::kPrismatic &&
                            ((type == ctl::MechanismType::kSlidingPivot && kind >= 10) ||
                             (type == ctl::MechanismType::kPlane && (kind == 12 || kind == 13))))
                               ? 0.4 * nu.head<3>().norm()
                               : 1e-7;
        EXPECT_NEAR(dj.second, fd, tol) << ctl::toString(type) << " trial " << trial << " tag " << tag;
      }
    }
  }
}

// A 2 kg part on a prismatic guide whose axis is 30° from the vertical, stops t ∈ [−0.2, 0.3]: it slides
// down the axis under its weight at the speed the axis's component of gravity gives (m g cos 30° / b_lin),
// never leaves the axis or turns, and rests on the lower stop, where the guide carries its whole weight.
TEST(ObjectGuide, APartOnATiltedAxisSlidesDownToItsStopWithoutLeavingTheAxis) {
  const SE3 base(mannequin::math::expSO3(Vector3(M_PI / 6, 0, 0)), Vector3(0.5, 0, 1.0));
  cs::RigidObject part(boxSpec(base));
  cs::ConstraintSolver solver({&part});
  sim::GuideRows guides({&part}, {0});
  solver.addProducer(&guides);
  guides.attach(0, mechanism(ctl::MechanismType::kPrismatic, base, {{-0.2, 0.3}}));
  const double b_lin = part.friction()(3, 3);
  const Vector3 axis = base.R.col(2);
  double worst_off = 0, worst_turn = 0;
  for (int k = 0; k < 3000; ++k) {
    part.computeFreeMotion(kGravity, kDt);
    solver.solve(kDt);
    if (k == 10) {  // sliding: the speed along the axis is gravity's component over b
      const double v = part.pointVelocity(part.pose().p).dot(axis);
      EXPECT_NEAR(v, 2.0 * kGravity.dot(axis) / b_lin, 1e-9);
      EXPECT_LT((part.pointVelocity(part.pose().p) - v * axis).norm(), 1e-9);
    }
    part.integrate(kDt);
    worst_off = std::max(worst_off, guides.positionError(0));
    worst_turn = std::max(worst_turn, guides.angleError(0));
  }
  std::printf("prismatic: t = %.6f (stop -0.2), worst off the axis %.2e m, turned %.2e rad, guide force z %.4f N\n",
              guides.coordinates(0)(0), worst_off, worst_turn, guides.force(0).z());
  EXPECT_NEAR(guides.coordinates(0)(0), -0.2, 1e-6);
  EXPECT_LT(worst_off, 1e-9);
  EXPECT_LT(worst_turn, 1e-9);
  // at rest on the stop the guide holds the weight: force = −m g
  EXPECT_LT((guides.force(0) + 2.0 * kGravity).norm(), 1e-6 * 2.0 * 9.81);
  EXPECT_LT(part.velocity().norm(), 1e-9);
}

// Attached 3 cm off the axis and turned 8°, the part comes onto it at no more than the recovery speed
// (no jump), and stays.
TEST(ObjectGuide, AttachedOffTheAxisThePartComesOntoItAtTheRecoverySpeed) {
  const SE3 base(Matrix3::Identity(), Vector3(0, 0, 1.0));
  const SE3 start(mannequin::math::expSO3(Vector3(0.14, 0, 0)), Vector3(0.03, 0, 1.0));
  cs::RigidObject part(boxSpec(start));
  cs::ConstraintSolver solver({&part});
  const double v_rec = 0.3;
  sim::GuideRows guides({&part}, {0}, 0.05, v_rec);
  solver.addProducer(&guides);
  guides.attach(0, mechanism(ctl::MechanismType::kPrismatic, base, {{-0.1, 0.1}}));
  EXPECT_NEAR(guides.positionError(0), 0.03, 1e-12);
  EXPECT_NEAR(guides.angleError(0), 0.14, 1e-12);
  double fastest = 0, fastest_turn = 0;
  for (int k = 0; k < 1000; ++k) {
    part.computeFreeMotion(Vector3::Zero(), kDt);
    solver.solve(kDt);
    const Vector3 v = part.pointVelocity(part.pose().p);
    fastest = std::max(fastest, std::hypot(v.x(), v.y()));
    fastest_turn = std::max(fastest_turn, (part.pose().R * part.velocity().head<3>()).norm());
    part.integrate(kDt);
  }
  std::printf("attached off the axis: fastest %.4f m/s, %.4f rad/s (recovery %.1f), now %.2e m / %.2e rad off\n", fastest,
              fastest_turn, v_rec, guides.positionError(0), guides.angleError(0));
  EXPECT_LE(fastest, v_rec * (1 + 1e-9));
  EXPECT_LE(fastest_turn, std::sqrt(3.0) * v_rec * (1 + 1e-9));  // per row (axis): at most √3 v_rec about a tilted axis
  EXPECT_LT(guides.positionError(0), 1e-9);
  EXPECT_LT(guides.angleError(0), 1e-9);
}

// Sliding pivot (the drill's guide): a torque about the axis turns the part at τ_z / b_zz, a torque across
// it tilts nothing, and a push along the axis moves it along.
TEST(ObjectGuide, ASlidingPivotLetsThePartTurnAndSlideAboutItsAxisOnly) {
  const SE3 base(Matrix3::Identity(), Vector3(0, 0, 1.0));
  cs::RigidObject part(boxSpec(base));
  cs::ConstraintSolver solver({&part});
  sim::GuideRows guides({&part}, {0});
  solver.addProducer(&guides);
  guides.attach(0, mechanism(ctl::MechanismType::kSlidingPivot, base));
  const double b_zz = part.friction()(2, 2), b_lin = part.friction()(3, 3);
  for (int k = 0; k < 500; ++k) {
    // a couple: 0.5 N·m about z and 2 N·m about x (two opposite forces 0.1 m apart), a 3 N push along z
    const Vector3 c = part.pose().p;
    part.addForce(c + Vector3(0.05, 0, 0), Vector3(0, 5, 0));
    part.addForce(c - Vector3(0.05, 0, 0), Vector3(0, -5, 0));
    part.addForce(c + Vector3(0, 0.05, 0), Vector3(0, 0, 20));
    part.addForce(c - Vector3(0, 0.05, 0), Vector3(0, 0, -20));
    part.addForce(c, Vector3(0, 0, 3));
    part.computeFreeMotion(Vector3::Zero(), kDt);
    solver.solve(kDt);
    if (k == 0) {
      EXPECT_NEAR((part.pose().R * part.velocity().head<3>()).z(), 0.5 / b_zz, 1e-9);
      EXPECT_NEAR(part.pointVelocity(c).z(), 3.0 / b_lin, 1e-9);
    }
    part.integrate(kDt);
    ASSERT_LT(guides.angleError(0), 1e-9) << "step " << k;
    ASSERT_LT(guides.positionError(0), 1e-9) << "step " << k;
  }
  EXPECT_NEAR(guides.coordinates(0)(1), 0.5 * 0.5 / b_zz, 1e-6);  // θ after 0.5 s
  EXPECT_NEAR(guides.coordinates(0)(0), 0.5 * 3.0 / b_lin, 1e-6);  // t
}

// Plane (the waiter's tray): a 1 kg tray with a 2 kg load pressing on its edge stays level and at its
// height; pushed sideways it slides in its plane; it turns about the vertical freely. detach() lets it go.
TEST(ObjectGuide, APlaneKeepsATrayLevelUnderAnOffCentreLoadAndLetsItSlide) {
  const SE3 base(Matrix3::Identity(), Vector3(0.4, 0.2, 1.1));
  cs::RigidObject tray(boxSpec(base, 1.0));
  cs::ConstraintSolver solver({&tray});
  sim::GuideRows guides({&tray}, {0});
  solver.addProducer(&guides);
  guides.attach(0, mechanism(ctl::MechanismType::kPlane, base));  // n locked at 0 by default
  const double b_lin = tray.friction()(3, 3);
  for (int k = 0; k < 1000; ++k) {
    tray.addForce(tray.pose().act(Vector3(0.15, 0.1, 0)), Vector3(0, 0, -2 * 9.81));
    tray.addForce(tray.pose().p, Vector3(4, 0, 0));
    tray.computeFreeMotion(kGravity, kDt);
    solver.solve(kDt);
    tray.integrate(kDt);
    ASSERT_LT(guides.angleError(0), 1e-9) << "step " << k;
    ASSERT_NEAR(tray.pose().p.z(), 1.1, 1e-9) << "step " << k;
  }
  // in the plane it moved at 4 N / b_lin; the guide holds the tray and its load: 3 kg · g up
  EXPECT_NEAR(tray.pose().p.x() - 0.4, 1.0 * 4.0 / b_lin, 1e-6);
  EXPECT_NEAR(guides.force(0).z(), 3.0 * 9.81, 1e-6);
  EXPECT_TRUE(guides.detach(0));
  EXPECT_FALSE(guides.detach(0));
  EXPECT_FALSE(guides.guided(0));
  tray.computeFreeMotion(kGravity, kDt);
  solver.solve(kDt);
  EXPECT_NEAR(tray.pointVelocity(tray.pose().p).z(), -9.81 * tray.timeConstant(), 1e-9);  // falls again
}

TEST(ObjectGuide, WhatAGuideCannotBeIsRefusedSayingWhy) {
  cs::RigidObject part(boxSpec(SE3()));
  cs::RigidObjectSpec door_spec = boxSpec(SE3());
  door_spec.name = "door";
  door_spec.hinge = mannequin::collision::HingeSpec{Vector3::UnitZ(), Vector3::Zero(), -1.0, 1.0};
  cs::RigidObject door(door_spec);
  sim::GuideRows guides({&part, &door}, {0, 1});
  std::string why;
  ctl::MechanismSpec curve = mechanism(ctl::MechanismType::kCurve, SE3());
  curve.points = {Vector3::Zero(), Vector3::UnitX()};
  EXPECT_FALSE(sim::GuideRows::supports(curve, &why));
  EXPECT_NE(why.find("curve"), std::string::npos) << why;
  ctl::MechanismSpec pushed = mechanism(ctl::MechanismType::kPlane, SE3());
  pushed.force = Eigen::Vector4d(0, 0, 0, -10);
  EXPECT_FALSE(sim::GuideRows::supports(pushed, &why));
  EXPECT_NE(why.find("force"), std::string::npos) << why;
  EXPECT_FALSE(sim::GuideRows::supports(mechanism(ctl::MechanismType::kSlidingPivot, SE3(), {{0, 1}}), &why));
  EXPECT_NE(why.find("2 pairs"), std::string::npos) << why;
  EXPECT_FALSE(sim::GuideRows::supports(mechanism(ctl::MechanismType::kPrismatic, SE3(), {{1, 0}}), &why));
  SE3 bad;
  bad.p.x() = std::nan("");
  EXPECT_FALSE(sim::GuideRows::supports(mechanism(ctl::MechanismType::kPrismatic, bad), &why));
  EXPECT_NE(why.find("finite"), std::string::npos) << why;
  EXPECT_TRUE(sim::GuideRows::supports(mechanism(ctl::MechanismType::kPrismatic, SE3(), {{-kInf, 0.2}}), &why));
  try {
    guides.attach(1, mechanism(ctl::MechanismType::kPrismatic, SE3()));
    FAIL() << "a hinged object was guided";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'door'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(guides.attach(0, curve), std::invalid_argument);
  EXPECT_THROW(guides.attach(2, mechanism(ctl::MechanismType::kPrismatic, SE3())), std::invalid_argument);
  EXPECT_FALSE(guides.guided(0));
  EXPECT_FALSE(guides.detach(0));
}

}  // namespace
