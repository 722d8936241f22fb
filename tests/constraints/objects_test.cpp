// Rigid objects (constraints::RigidObject), hinge limits and grasps through the ConstraintSolver (thesis 3.2,
// 4.3.1, Fig. 3.6): each test steps free motion → solver → integration, like the World.
#include "object_step.hpp"
#include "mannequin/constraints/objects.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>

#include "mannequin/collision/world.hpp"
#include "mannequin/constraints/contacts.hpp"
#include "mannequin/constraints/solver.hpp"

namespace {

using mannequin::math::Matrix3;
using mannequin::math::SE3;
using mannequin::math::Vector3;
using mannequin::math::Vector6;
namespace cs = mannequin::constraints;
namespace sim = mannequin::sim;

using mannequin::testing::kDt;
using mannequin::testing::kGravity;

// Contacts of points of a RigidObject with a static plane {x : n·x = offset} (the test's own producer,
// independent of constraints::ContactRows): per point, d = n·p − offset − radius, J = nᵀ J_p(p − r n),
// friction edges on t1, t2 (t1 given, t2 = n × t1).
class PlaneContacts final : public cs::RowProducer {
 public:
  struct Point {
    const cs::RigidObject* object;
    int system;
    Vector3 local;   // body frame
    double radius;   // sphere radius at the point (0: a vertex)
  };
  PlaneContacts(std::vector<Point> points, const Vector3& n, double offset, double mu, const Vector3& t1)
      : points_(std::move(points)), n_(n.normalized()), offset_(offset), mu_(mu) {
    t1_ = (t1 - t1.dot(n_) * n_).normalized();
    t2_ = n_.cross(t1_);
    J_.setZero(3, 6);
  }
  const char* name() const override { return "plane_contacts"; }
  void addRows(int id, double, cs::RowSet& rows) override {
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Point& pt = points_[i];
      const Vector3 p = pt.object->pose(0).act(pt.local) - pt.radius * n_;
      cs::RowInfo info;
      info.source = cs::RowSource::kContact;
      info.producer = id;
      info.tag = static_cast<int>(i);
      info.distance = n_.dot(p) - offset_;
      info.mu = mu_;
      info.friction_edges = mu_ > 0 ? 4 : 0;
      info.system_a = pt.system;
      const int r = rows.add(info);
      ASSERT_GE(r, 0);
      const int nv = pt.object->nv();
      auto J = J_.leftCols(nv);
      pt.object->pointJacobian(0, p, J);
      rows.jacobian(r, pt.system) = n_.transpose() * J;
      if (mu_ > 0) {
        rows.tangent(r, pt.system, 0) = t1_.transpose() * J;
        rows.tangent(r, pt.system, 1) = t2_.transpose() * J;
      }
    }
  }
  void solved(int id, const cs::RowSet& rows) override {
    normal_sum = 0;
    for (int r = 0; r < rows.size(); ++r)
      if (rows.info(r).producer == id) normal_sum += rows.info(r).lambda;
  }
  double normal_sum = 0;

 private:
  std::vector<Point> points_;
  Vector3 n_, t1_, t2_;
  double offset_, mu_;
  Eigen::Matrix3Xd J_;
};

// A "hand": a 6-dof system whose velocity is the world twist (ω, v) of its origin, ṗ(x) = v + ω × (x − o),
// with first-order dynamics b q̇ = Γ and a P controller as its free motion (q̇_free = K·error + feed-forward),
// like the mannequin's controller. Records the constraint force Γ_c it receives.
class TestHand final : public cs::ConstrainedSystem, public cs::BodyFrames {
 public:
  TestHand(const SE3& pose, double b_rot, double b_lin) : target_(pose), pose_(pose) {
    b_ = Eigen::MatrixXd::Zero(6, 6);
    b_.diagonal() << b_rot, b_rot, b_rot, b_lin, b_lin, b_lin;
    factor_.compute(b_);
    qdot_free_ = Eigen::VectorXd::Zero(6);
    qdot_ = qdot_free_;
    gamma_ = qdot_free_;
  }
  int nv() const override { return 6; }
  const Eigen::VectorXd& qdotFree() const override { return qdot_free_; }
  const mannequin::math::TreeCholesky& frictionFactor() const override { return factor_; }
  bool applyConstraintForce(const Eigen::VectorXd& g) override {
    gamma_ = g;
    qdot_ += b_.diagonal().cwiseInverse().cwiseProduct(g);
    return true;
  }
  const SE3& pose(int) const override { return pose_; }
  void pointJacobian(int, const Vector3& p, Eigen::Ref<Eigen::Matrix3Xd> J) const override {
    J.leftCols<3>() = -mannequin::math::hat(p - pose_.p);
    J.rightCols<3>() = Matrix3::Identity();
  }
  void freeMotion(const Vector3& v_ff) {
    qdot_free_.head<3>() = gain * mannequin::math::logSO3(target_.R * pose_.R.transpose());
    qdot_free_.tail<3>() = gain * (target_.p - pose_.p) + v_ff;
    qdot_ = qdot_free_;
    gamma_.setZero();
  }
  void integrate(double dt) {
    pose_.R = mannequin::math::expSO3(dt * qdot_.head<3>()) * pose_.R;
    pose_.p += dt * qdot_.tail<3>();
  }
  SE3 target_;
  double gain = 20.0;
  const Eigen::VectorXd& gamma() const { return gamma_; }

 private:
  SE3 pose_;
  Eigen::MatrixXd b_;
  mannequin::math::TreeCholesky factor_ = mannequin::math::TreeCholesky::dense(6);
  Eigen::VectorXd qdot_free_, qdot_, gamma_;
};

cs::RigidObjectSpec ballSpec(const Vector3& p) {
  cs::RigidObjectSpec s;
  s.name = "ball";
  s.pose.p = p;
  s.mass = 0.45;
  s.inertia = Vector3::Constant(0.4 * 0.45 * 0.11 * 0.11);
  return s;
}

// ---------------------------------------------------------------------------------------------------
TEST(RigidObject, PointJacobianMatchesFiniteDifferencesFree) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  cs::RigidObjectSpec spec;
  spec.name = "box";
  spec.pose = SE3(mannequin::math::expSO3(Vector3(0.3, -0.7, 1.1)), Vector3(0.2, -0.1, 0.9));
  cs::RigidObject obj(spec);
  Eigen::Matrix3Xd J(3, 6);
  for (int trial = 0; trial < 20; ++trial) {
    const Vector3 pl(u(rng), u(rng), u(rng));
    Vector6 nu;
    for (int i = 0; i < 6; ++i) nu[i] = u(rng);
    const Vector3 p = obj.pose().act(pl);
    obj.pointJacobian(0, p, J);
    const double h = 1e-6;
    // Ḣ = H[ν]: H(ε) = H exp(εν)
    const Vector3 fd =
        ((obj.pose() * mannequin::math::expSE3(h * nu)).act(pl) - (obj.pose() * mannequin::math::expSE3(-h * nu)).act(pl)) /
        (2 * h);
    EXPECT_LT((J * nu - fd).norm(), 1e-8) << "trial " << trial;
  }
}

TEST(RigidObject, PointJacobianMatchesFiniteDifferencesHinge) {
  cs::RigidObjectSpec spec;
  spec.name = "door";
  spec.pose.p = Vector3(0.45, 0.3, 1.0);
  spec.hinge = mannequin::collision::HingeSpec{Vector3(0.2, 0.1, 1.0), Vector3(0, 0.3, 0), -1, 1};
  cs::RigidObject obj(spec);
  Eigen::Matrix3Xd J(3, 1);
  for (double theta : {-0.5, 0.0, 0.7}) {
    obj.setAngle(theta);
    const Vector3 pl(0.4, -0.2, 0.3);
    const Vector3 p = obj.pose().act(pl);
    obj.pointJacobian(0, p, J);
    const double h = 1e-6;
    obj.setAngle(theta + h);
    const Vector3 pp = obj.pose().act(pl);
    obj.setAngle(theta - h);
    const Vector3 pm = obj.pose().act(pl);
    obj.setAngle(theta);
    EXPECT_LT((J.col(0) - (pp - pm) / (2 * h)).norm(), 1e-8) << "theta " << theta;
    // a point on the axis does not move
    obj.pointJacobian(0, spec.hinge->point + 0.7 * spec.hinge->axis, J);
    EXPECT_LT(J.norm(), 1e-12);
  }
}

// b = diag(I/τ, m/τ): a free body falls at the terminal speed g τ at once (first-order dynamics).
TEST(RigidObject, FallsAtTerminalSpeedGTau) {
  cs::RigidObject ball(ballSpec(Vector3(0, 0, 2)));
  cs::ConstraintSolver solver({&ball});
  for (int k = 0; k < 100; ++k) {
    ball.computeFreeMotion(kGravity, kDt);
    solver.solve(kDt);
    ball.integrate(kDt);
  }
  EXPECT_NEAR(ball.pointVelocity(ball.pose().p).z(), -9.81 * 0.05, 1e-12);
  EXPECT_NEAR(ball.pose().p.z(), 2 - 0.1 * 9.81 * 0.05, 1e-9);
}

// Fig. 3.6: a 0.45 kg ball dropped on a table top comes to rest on it; the contact force is its weight.
TEST(RigidObject, BallRestsOnTableWithItsWeightAsContactForce) {
  const double top = 0.75, r = 0.11;
  cs::RigidObject ball(ballSpec(Vector3(0.9, 0.2, top + r + 0.01)));
  cs::ConstraintSolver solver({&ball});
  PlaneContacts table({{&ball, 0, Vector3::Zero(), r}}, Vector3::UnitZ(), top, 0.8, Vector3::UnitX());
  solver.addProducer(&table);
  double lowest = 1e9;
  for (int k = 0; k < 1000; ++k) {
    ball.computeFreeMotion(kGravity, kDt);
    solver.solve(kDt);
    ball.integrate(kDt);
    lowest = std::min(lowest, ball.pose().p.z() - r - top);
    ASSERT_FALSE(solver.report().fallback) << "step " << k;
  }
  // the predictive row keeps d ≥ 0 to first order: the sphere's distance is linear in its height
  EXPECT_GT(lowest, -1e-9);
  EXPECT_LT(ball.pose().p.z() - r - top, 1e-6);  // landed
  EXPECT_NEAR(table.normal_sum, 0.45 * 9.81, 0.01 * 0.45 * 9.81);
  std::printf("ball: normal force %.9f N (m g = %.9f N), lowest gap %.3g m\n", table.normal_sum, 0.45 * 9.81, lowest);
  EXPECT_LT(ball.velocity().norm(), 1e-9);
}

// Coulomb friction on a 20° slope: tan 20° = 0.364. A box on 4 vertices stays with μ = 0.8 and slides
// with μ = 0.2 at the first-order speed τ g (sin α − μ cos α) (b_lin v = the net tangential force).
double slideOnSlope(double mu, double seconds) {
  const double alpha = 20 * M_PI / 180;
  const Vector3 n(-std::sin(alpha), 0, std::cos(alpha));  // the slope rises towards +x
  const Vector3 down_slope(-std::cos(alpha), 0, -std::sin(alpha));
  cs::RigidObjectSpec spec;
  spec.name = "box";
  spec.mass = 2.0;
  spec.inertia = Vector3(0.01, 0.01, 0.015);
  const Vector3 half(0.1, 0.1, 0.05);
  spec.pose.R = Eigen::AngleAxisd(-alpha, Vector3::UnitY()).toRotationMatrix();  // R e_z = n
  spec.pose.p = (half.z() + 0.001) * n;
  cs::RigidObject box(spec);
  std::vector<PlaneContacts::Point> pts;
  for (int c = 0; c < 4; ++c)
    pts.push_back({&box, 0, Vector3((c & 1) ? half.x() : -half.x(), (c & 2) ? half.y() : -half.y(), -half.z()), 0.0});
  PlaneContacts slope(pts, n, 0.0, mu, down_slope);
  cs::ConstraintSolver solver({&box});
  solver.addProducer(&slope);
  const int steps = static_cast<int>(seconds / kDt);
  Vector3 start = Vector3::Zero();
  for (int k = 0; k < steps; ++k) {
    if (k == 100) start = box.pose().p;  // landed (1 mm at g τ takes 2 ms)
    box.computeFreeMotion(kGravity, kDt);
    solver.solve(kDt);
    EXPECT_FALSE(solver.report().fallback) << "step " << k;
    box.integrate(kDt);
  }
  EXPECT_NEAR(slope.normal_sum, 2.0 * 9.81 * std::cos(alpha), 0.01 * 2.0 * 9.81);
  const double moved = (box.pose().p - start).dot(down_slope);
  std::printf("slope mu %.1f: normal %.6f N (m g cos = %.6f), moved %.6g m in %.1f s\n", mu, slope.normal_sum,
              2.0 * 9.81 * std::cos(alpha), moved, seconds - 0.1);
  EXPECT_LT(std::abs((box.pose().p - start).dot(n)), 1e-6);  // stays on the slope
  return moved / (seconds - 0.1);
}

TEST(RigidObject, BoxOnSlopeSticksWithHighFriction) {
  const double speed = slideOnSlope(0.8, 1.0);
  EXPECT_LT(std::abs(speed), 1e-6);  // m/s
}

TEST(RigidObject, BoxOnSlopeSlidesWithLowFriction) {
  const double alpha = 20 * M_PI / 180;
  const double expected = 0.05 * 9.81 * (std::sin(alpha) - 0.2 * std::cos(alpha));  // 0.0757 m/s
  const double speed = slideOnSlope(0.2, 1.0);
  EXPECT_NEAR(speed, expected, 0.02 * expected);
}

// A door on a vertical hinge pushed by a horizontal point force turns about its axis only, at
// θ̇ = a·(r × F)/b, and stops at its upper limit.
TEST(RigidObject, DoorTurnsAboutItsHingeAndStopsAtTheLimit) {
  cs::RigidObjectSpec spec;
  spec.name = "door";
  spec.mass = 20;
  spec.inertia = Vector3(20 * (0.81 + 4) / 12, 20 * (4 + 0.0016) / 12, 20 * (0.81 + 0.0016) / 12);
  spec.pose.p = Vector3(0.45, 0, 1.0);  // leaf along x from the axis
  spec.hinge = mannequin::collision::HingeSpec{Vector3::UnitZ(), Vector3::Zero(), 0.0, 100 * M_PI / 180};
  cs::RigidObject door(spec);
  const double b = door.friction()(0, 0);
  // I_axis = Izz + m (0.45)²
  EXPECT_NEAR(b, (spec.inertia.z() + 20 * 0.45 * 0.45) / 0.05, 1e-9);
  cs::ConstraintSolver solver({&door});
  cs::HingeLimitRows limits({{&door, 0}});
  solver.addProducer(&limits);
  double worst = 0;
  for (int k = 0; k < 12000; ++k) {
    // 60 N pushing the leaf at 0.4 m from the axis, along the leaf's normal (+y at θ = 0): θ̇ > 0 about +z
    const Vector3 handle = door.pose().act(Vector3(0.4, 0, 0));
    const Vector3 F = 60.0 * door.pose().R.col(1);
    door.addForce(handle, F);
    door.computeFreeMotion(kGravity, kDt);
    solver.solve(kDt);
    if (k == 0) {
      EXPECT_NEAR(door.velocity()[0], Vector3::UnitZ().dot(handle.cross(F)) / b, 1e-12);
      EXPECT_NEAR(door.velocity()[0], 60 * 0.85 / b, 1e-12);  // r = 0.45 + 0.4 from the axis
      // the axis does not move, the handle moves tangentially
      EXPECT_LT(door.pointVelocity(Vector3(0, 0, 0.3)).norm(), 1e-15);
      EXPECT_NEAR(door.pointVelocity(handle).dot(handle), 0.0, 1e-12);
    }
    door.integrate(kDt);
    worst = std::max(worst, door.angle() - spec.hinge->upper);
    // the door stays on its hinge: height and distance of its centre from the axis
    ASSERT_NEAR(door.pose().p.z(), 1.0, 1e-12);
    ASSERT_NEAR(door.pose().p.head<2>().norm(), 0.45, 1e-9);
  }
  std::printf("door: angle - upper = %.3g rad, worst excess %.3g rad\n", door.angle() - spec.hinge->upper, worst);
  EXPECT_NEAR(door.angle(), spec.hinge->upper, 1e-6);
  EXPECT_LT(worst, 1e-6);
}

// A lever on a horizontal pivot, centre of mass above it, falls onto its end stop and rests there;
// the stop holds the gravity torque.
TEST(RigidObject, LeverRestsOnItsEndStop) {
  cs::RigidObjectSpec spec;
  spec.name = "lever";
  spec.mass = 0.3;
  spec.inertia = Vector3(0.001, 0.001, 0.0001);
  spec.pose.p = Vector3(0.7, -0.8, 1.025);
  spec.pose.R = Eigen::AngleAxisd(0.05, Vector3::UnitY()).toRotationMatrix();
  spec.hinge = mannequin::collision::HingeSpec{Vector3::UnitY(), Vector3(0.7, -0.8, 0.9), -M_PI / 6, M_PI / 6};
  // tilt the centre of mass slightly towards +x so gravity turns the lever towards +θ about y
  spec.pose.p = Vector3(0.7, -0.8, 0.9) + Eigen::AngleAxisd(0.05, Vector3::UnitY()) * Vector3(0, 0, 0.125);
  cs::RigidObject lever(spec);
  cs::ConstraintSolver solver({&lever});
  cs::HingeLimitRows limits({{&lever, 0}});
  solver.addProducer(&limits);
  double worst = 0;
  for (int k = 0; k < 5000; ++k) {
    lever.computeFreeMotion(kGravity, kDt);
    solver.solve(kDt);
    lever.integrate(kDt);
    worst = std::max({worst, lever.angle() - spec.hinge->upper, spec.hinge->lower - lever.angle()});
  }
  EXPECT_NEAR(lever.angle(), M_PI / 6, 1e-6);
  EXPECT_LT(worst, 1e-6);
  // the stop's torque balances gravity: λ = m g ℓ sin(0.05 + π/6)
  ASSERT_GE(solver.rows().size(), 1);
  double lambda = 0;
  for (int r = 0; r < solver.rows().size(); ++r)
    if (solver.rows().info(r).source == cs::RowSource::kHinge) lambda += solver.rows().info(r).lambda;
  std::printf("lever: angle - upper = %.3g rad, worst excess %.3g, stop torque %.9f N·m (gravity %.9f)\n",
              lever.angle() - M_PI / 6, worst, lambda, 0.3 * 9.81 * 0.125 * std::sin(0.05 + M_PI / 6));
  EXPECT_NEAR(lambda, 0.3 * 9.81 * 0.125 * std::sin(0.05 + M_PI / 6), 1e-6);
}

// Grasp: the object follows the hand over 1 m without slipping, its weight is the force on the hand,
// and it falls when released.
TEST(Grasp, HeldObjectFollowsTheHandAndWeighsOnIt) {
  TestHand hand(SE3(Matrix3::Identity(), Vector3(0, 0, 1.2)), 2.0, 200.0);
  cs::RigidObjectSpec spec;
  spec.name = "tray";
  spec.mass = 0.6;
  spec.inertia = Vector3(0.003, 0.006, 0.009);
  spec.pose = SE3(Eigen::AngleAxisd(0.3, Vector3::UnitZ()).toRotationMatrix(), Vector3(0.05, 0.02, 1.1));
  cs::RigidObject tray(spec);
  cs::ConstraintSolver solver({&hand, &tray});
  cs::GraspRows grasps({&tray}, {1}, 6);
  solver.addProducer(&grasps);
  const int g = grasps.grasp({0, &hand, 0}, 0);
  ASSERT_GE(g, 0);
  EXPECT_TRUE(grasps.held(0));
  EXPECT_EQ(grasps.grasp({0, &hand, 0}, 0), -1);  // already held
  const SE3 hMo = hand.pose(0).inverse() * tray.pose(0);
  const auto step = [&](const Vector3& v_ff) {
    hand.freeMotion(v_ff);
    tray.computeFreeMotion(kGravity, kDt);
    solver.solve(kDt);
    EXPECT_FALSE(solver.report().fallback);
    hand.integrate(kDt);
    tray.integrate(kDt);
  };
  const auto relativeError = [&](double& pos, double& rot) {
    const SE3 err = (hand.pose(0) * hMo).inverse() * tray.pose(0);
    pos = err.p.norm();
    rot = mannequin::math::logSO3(err.R).norm();
  };
  // hold still: the hand settles where its controller balances the weight
  for (int k = 0; k < 1000; ++k) step(Vector3::Zero());
  const double mg = 0.6 * 9.81;
  EXPECT_NEAR(hand.gamma()[5], -mg, 0.01 * mg);                     // force on the hand: the weight, down
  EXPECT_LT(hand.gamma().segment<2>(3).norm(), 0.01 * mg);
  EXPECT_NEAR(grasps.force(g).z(), mg, 0.01 * mg);                  // on the tray: up
  std::printf("grasp at rest: force on the hand %.9f N (m g = %.9f N)\n", -hand.gamma()[5], mg);
  // the moment of the weight about the hand's origin reaches the hand too: r × (−m g e_z)
  const Vector3 r = tray.pose(0).p - hand.pose(0).p;
  EXPECT_LT((hand.gamma().head<3>() - r.cross(Vector3(0, 0, -mg))).norm(), 0.01 * mg * r.norm() + 1e-9);
  // move 1 m along x in 2 s (smooth speed profile), turning the hand by 0.5 rad about z on the way
  double worst_pos = 0, worst_rot = 0;
  const Vector3 start = hand.pose(0).p;
  const Matrix3 R0 = hand.target_.R;
  for (int k = 0; k < 2000; ++k) {
    const double s = k * kDt / 2.0;
    const double prog = s - std::sin(2 * M_PI * s) / (2 * M_PI);
    const double speed = (1 - std::cos(2 * M_PI * s)) / 2.0;  // d prog / dt (m/s)
    hand.target_.p = Vector3(0, 0, 1.2) + Vector3(prog, 0, 0);
    hand.target_.R = Eigen::AngleAxisd(0.5 * prog, Vector3::UnitZ()).toRotationMatrix() * R0;
    step(Vector3(speed, 0, 0));
    double pos = 0, rot = 0;
    relativeError(pos, rot);
    worst_pos = std::max(worst_pos, pos);
    worst_rot = std::max(worst_rot, rot);
  }
  for (int k = 0; k < 300; ++k) step(Vector3::Zero());
  EXPECT_GT((hand.pose(0).p - start).x(), 0.99);
  EXPECT_LT(worst_pos, 1e-3);
  EXPECT_LT(worst_rot, 1e-3);
  RecordProperty("grasp_max_position_error_m", std::to_string(worst_pos));
  RecordProperty("grasp_max_orientation_error_rad", std::to_string(worst_rot));
  std::printf("grasp: max relative error %.3g m, %.3g rad over 1 m\n", worst_pos, worst_rot);
  // release: the tray falls at g τ, the hand carries nothing
  ASSERT_TRUE(grasps.release(g));
  EXPECT_FALSE(grasps.release(g));
  EXPECT_EQ(grasps.numGrasps(), 0);
  const double z0 = tray.pose(0).p.z();
  for (int k = 0; k < 200; ++k) step(Vector3::Zero());
  EXPECT_NEAR(tray.pose(0).p.z() - z0, -0.2 * 9.81 * 0.05, 1e-9);
  EXPECT_LT(hand.gamma().norm(), 1e-12);
}

// makeObjects: the scene's movable bodies with dynamics become objects, in order.
TEST(RigidObject, MakeObjectsFromAScene) {
  const auto scene = mannequin::collision::parseScene(
      "bodies:\n"
      "  - {name: floor, shape: {type: plane}}\n"
      "  - {name: tool, movable: true, shape: {type: sphere, radius: 0.1}}\n"
      "  - {name: ball, movable: true, mass: 0.45, shape: {type: sphere, radius: 0.11}}\n"
      "  - name: lever\n"
      "    movable: true\n"
      "    mass: 0.3\n"
      "    time_constant: 0.2\n"
      "    hinge: {axis: [0, 1, 0], limits_deg: [-30, 30]}\n"
      "    shape: {type: capsule, radius: 0.012, length: 0.2}\n",
      "test.yaml");
  std::vector<int> index;
  const std::vector<cs::RigidObject> objects = cs::makeObjects(scene, &index, 0.05);
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(index, (std::vector<int>{2, 3}));
  EXPECT_EQ(objects[0].name(), "ball");
  EXPECT_EQ(objects[0].nv(), 6);
  EXPECT_DOUBLE_EQ(objects[0].friction()(3, 3), 0.45 / 0.05);
  EXPECT_EQ(objects[1].nv(), 1);
  EXPECT_DOUBLE_EQ(objects[1].timeConstant(), 0.2);
  EXPECT_NEAR(objects[1].hinge().upper, M_PI / 6, 1e-15);
}

// A shipped scene wired as the World wires it: makeObjects, a CollisionWorld, constraints::ContactRows
// with the objects' bindings, HingeLimitRows over the objects; per step: query, free motion, solve,
// integrate, setBodyPose.
struct SceneRig {
  explicit SceneRig(const std::string& file) {
    const char* root = std::getenv("MANNEQUIN_SOURCE_DIR");
    scene = mannequin::collision::loadScene(std::string(root ? root : ".") + "/configs/scenes/" + file);
    std::vector<int> index;
    objects = cs::makeObjects(scene, &index, 0.05);
    cw.addScene(scene);
    std::vector<cs::ConstrainedSystem*> systems;
    for (auto& o : objects) systems.push_back(&o);
    std::vector<cs::BodyBinding> bindings(static_cast<std::size_t>(cw.bodyCount()));
    for (int b = 0; b < cw.bodyCount(); ++b) {
      bindings[b].static_pose = cw.bodyPose(b);
      bindings[b].margin = cw.margin(b);
    }
    std::vector<cs::HingeLimitRows::Entry> hinged;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const int b = cw.findBody("scene/" + scene.bodies[index[i]].name);
      object_body.push_back(b);
      bindings[b].system = static_cast<int>(i);
      bindings[b].frames = &objects[i];
      bindings[b].local = 0;
      hinged.push_back({&objects[i], static_cast<int>(i)});
    }
    contacts = std::make_unique<cs::ContactRows>(bindings);
    limits = std::make_unique<cs::HingeLimitRows>(hinged);
    solver = std::make_unique<cs::ConstraintSolver>(systems);
    solver->addProducer(contacts.get());
    solver->addProducer(limits.get());
  }
  int object(const std::string& name) const {
    for (std::size_t i = 0; i < objects.size(); ++i)
      if (objects[i].name() == name) return static_cast<int>(i);
    return -1;
  }
  bool step(std::uint64_t k) {
    cw.query(k, set);
    contacts->setContacts(set);
    for (auto& o : objects) o.computeFreeMotion(kGravity, kDt);
    solver->solve(kDt);
    for (std::size_t i = 0; i < objects.size(); ++i) {
      objects[i].integrate(kDt);
      cw.setBodyPose(object_body[i], objects[i].pose());
    }
    return !solver->report().fallback;
  }
  // vertical force the contacts applied on object i at the last solve (N)
  double contactForceZ(int i) const {
    double fz = 0;
    for (std::size_t c = 0; c < contacts->contacts().size(); ++c) {
      const auto& ct = contacts->contacts()[c];
      // the normal goes from a to b: the force on b is +λ n, on a −λ n
      if (ct.body_b == object_body[i]) fz += contacts->states()[c].normal_force * ct.normal.z();
      if (ct.body_a == object_body[i]) fz -= contacts->states()[c].normal_force * ct.normal.z();
    }
    return fz;
  }
  mannequin::collision::SceneSpec scene;
  std::vector<cs::RigidObject> objects;
  mannequin::collision::CollisionWorld cw;
  std::vector<int> object_body;
  std::unique_ptr<cs::ContactRows> contacts;
  std::unique_ptr<cs::HingeLimitRows> limits;
  std::unique_ptr<cs::ConstraintSolver> solver;
  mannequin::collision::ContactSet set;
};

// Fig. 3.6 on the shipped table scene: the ball (0.45 kg) and the tray (0.6 kg) rest on the table top
// with their weights as contact forces.
TEST(RigidObject, TableSceneObjectsRestThroughContactRows) {
  SceneRig rig("table.yaml");
  ASSERT_EQ(rig.objects.size(), 2u);  // ball, tray (the tool is kinematic)
  for (int k = 0; k < 1000; ++k) ASSERT_TRUE(rig.step(static_cast<std::uint64_t>(k))) << "step " << k;
  for (std::size_t i = 0; i < rig.objects.size(); ++i) {
    const double fz = rig.contactForceZ(static_cast<int>(i)), mg = rig.objects[i].mass() * 9.81;
    std::printf("%s: contact force %.6f N (m g = %.6f N), speed %.3g\n", rig.objects[i].name().c_str(), fz, mg,
                rig.objects[i].velocity().norm());
    EXPECT_NEAR(fz, mg, 0.01 * mg) << rig.objects[i].name();
    EXPECT_LT(rig.objects[i].velocity().norm(), 1e-6) << rig.objects[i].name();
  }
  EXPECT_LT(rig.contacts->maxPenetration(), 1e-4);
}

// The shipped door_lever scene: the door, pushed open, swings clear of its frame to its 100° stop;
// the lever, tipped, falls onto its 30° stop clear of its base.
TEST(RigidObject, DoorLeverSceneReachesItsStops) {
  SceneRig rig("door_lever.yaml");
  const int door = rig.object("door"), lever = rig.object("lever");
  ASSERT_GE(door, 0);
  ASSERT_GE(lever, 0);
  cs::RigidObject& D = rig.objects[door];
  cs::RigidObject& L = rig.objects[lever];
  L.setAngle(0.02);  // off its unstable upright balance
  for (int k = 0; k < 6000; ++k) {
    // 60 N on the leaf's latch end, along its −x normal (the opening direction)
    D.addForce(D.pose().act(Vector3(0, -0.4, 0)), -60.0 * D.pose().R.col(0));
    ASSERT_TRUE(rig.step(static_cast<std::uint64_t>(k))) << "step " << k;
  }
  std::printf("door %.9f rad (stop %.9f), lever %.9f rad (stop %.9f), contacts %zu\n", D.angle(), D.hinge().upper,
              L.angle(), L.hinge().upper, rig.contacts->contacts().size());
  EXPECT_NEAR(D.angle(), 100 * M_PI / 180, 1e-6);
  EXPECT_NEAR(L.angle(), 30 * M_PI / 180, 1e-6);
  for (std::size_t c = 0; c < rig.contacts->contacts().size(); ++c)
    EXPECT_EQ(rig.contacts->states()[c].normal_force, 0.0)
        << rig.cw.bodyName(rig.contacts->contacts()[c].body_a) << " / " << rig.cw.bodyName(rig.contacts->contacts()[c].body_b);
}

TEST(RigidObject, BadSpecsAreRefused) {
  cs::RigidObjectSpec s = ballSpec(Vector3::Zero());
  s.mass = -1;
  EXPECT_THROW(cs::RigidObject{s}, std::invalid_argument);
  s = ballSpec(Vector3::Zero());
  s.time_constant = std::nan("");
  EXPECT_THROW(cs::RigidObject{s}, std::invalid_argument);
  s = ballSpec(Vector3::Zero());
  s.hinge = mannequin::collision::HingeSpec{Vector3::Zero(), Vector3::Zero(), -1, 1};
  EXPECT_THROW(cs::RigidObject{s}, std::invalid_argument);
  s.hinge = mannequin::collision::HingeSpec{Vector3::UnitZ(), Vector3::Zero(), 0.1, 1};
  EXPECT_THROW(cs::RigidObject{s}, std::invalid_argument);
}

}  // namespace
