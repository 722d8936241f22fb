#include "mannequin/collision/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "test_util.hpp"

using namespace mannequin;
using namespace mannequin::collision;
using collision::test::worldA;
using collision::test::worldB;

namespace {

constexpr double kPi = 3.14159265358979323846;

SE3 at(const Vector3& p, const math::Matrix3& R = math::Matrix3::Identity()) { return SE3(R, p); }
math::Matrix3 rotY(double a) { return rpy(0, a, 0); }

CollisionWorld floorWorld(double activation = 1.0) {
  WorldOptions o;
  o.activation_distance = activation;
  CollisionWorld w(o);
  w.addBody("scene/floor", {{Shape::plane(Vector3::UnitZ(), 0.0), SE3()}}, SE3(), BodyKind::kStatic);
  return w;
}

std::vector<Contact> between(const CollisionWorld& w, const ContactSet& cs, const std::string& a, const std::string& b) {
  std::vector<Contact> out;
  for (const auto& c : cs.contacts)
    if (w.bodyName(c.body_a) == a && w.bodyName(c.body_b) == b) out.push_back(c);
  return out;
}

// every contact: unit normal and distance == n·(pb − pa) in the world
void expectConsistent(const CollisionWorld& w, const ContactSet& cs) {
  for (const auto& c : cs.contacts) {
    EXPECT_LT(c.body_a, c.body_b);
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
    EXPECT_NEAR(c.distance, c.normal.dot(worldB(w, c) - worldA(w, c)), 1e-9)
        << w.bodyName(c.body_a) << " / " << w.bodyName(c.body_b);
  }
}

skeleton::Model mannequinModel(const char* name = "male_50th") {
  return skeleton::buildMannequin(
      skeleton::loadMannequinSpec(test::sourcePath(std::string("configs/mannequins/") + name + ".yaml")));
}

}  // namespace

TEST(CollisionWorld, CapsuleUprightOnPlaneOnePoint) {
  CollisionWorld w = floorWorld(0.3);  // the upper end (0.65 m up) is out of range
  const int cap = w.addBody("cap", {{Shape::capsule(0.05, 0.4), SE3()}}, at({0.1, 0.2, 0.5}), BodyKind::kMovable);
  ContactSet cs;
  w.query(7, cs);
  EXPECT_EQ(cs.step, 7u);
  ASSERT_EQ(cs.contacts.size(), 1u);
  const Contact& c = cs.contacts[0];
  EXPECT_EQ(c.body_a, 0);
  EXPECT_EQ(c.body_b, cap);
  EXPECT_NEAR(c.distance, 0.5 - 0.2 - 0.05, 1e-14);
  EXPECT_TRUE(c.normal.isApprox(Vector3::UnitZ()));
  EXPECT_TRUE(c.point_a.isApprox(Vector3(0.1, 0.2, 0.0)));
  EXPECT_TRUE(c.point_b.isApprox(Vector3(0, 0, -0.25)));
}

TEST(CollisionWorld, CapsuleLyingOnPlaneTwoPointsTiltedOne) {
  CollisionWorld w = floorWorld();
  const int cap = w.addBody("cap", {{Shape::capsule(0.05, 0.4), SE3()}}, at({0.3, 0, 0.08}, rotY(kPi / 2)),
                            BodyKind::kMovable);
  ContactSet cs;
  w.query(0, cs);
  ASSERT_EQ(cs.contacts.size(), 2u);
  std::set<double> xs;
  for (const auto& c : cs.contacts) {
    EXPECT_NEAR(c.distance, 0.03, 1e-14);
    EXPECT_TRUE(c.normal.isApprox(Vector3::UnitZ()));
    EXPECT_NEAR(worldA(w, c).z(), 0.0, 1e-14);
    EXPECT_NEAR(worldB(w, c).z(), 0.03, 1e-14);
    xs.insert(std::round(worldB(w, c).x() * 1e9) / 1e9);
  }
  EXPECT_EQ(xs, (std::set<double>{0.1, 0.5}));
  // tilted by 30° from the horizontal: only the lower end is in range (activation 2 cm)
  w.setActivationDistance(0.02);
  w.setBodyPose(cap, at({0.3, 0, 0.2 * std::sin(kPi / 6) + 0.05 + 0.01}, rotY(kPi / 2 - kPi / 6)));
  w.query(1, cs);
  ASSERT_EQ(cs.contacts.size(), 1u);
  EXPECT_NEAR(cs.contacts[0].distance, 0.01, 1e-14);
  expectConsistent(w, cs);
}

TEST(CollisionWorld, CapsuleBoxFaceEdgeAndPenetration) {
  WorldOptions o;
  o.activation_distance = 0.1;
  CollisionWorld w(o);
  w.addBody("box", {{Shape::box({1.0, 0.6, 0.2}), SE3()}}, SE3(), BodyKind::kStatic);
  // lying along y on the top face, 4 cm above: the two ends
  const int cap = w.addBody("cap", {{Shape::capsule(0.05, 0.4), SE3()}},
                            at({0.2, 0, 0.1 + 0.05 + 0.04}, rpy(kPi / 2, 0, 0)), BodyKind::kMovable);
  ContactSet cs;
  w.query(0, cs);
  ASSERT_EQ(cs.contacts.size(), 2u);
  for (const auto& c : cs.contacts) {
    EXPECT_NEAR(c.distance, 0.04, 1e-12);
    EXPECT_TRUE(c.normal.isApprox(Vector3::UnitZ()));
    EXPECT_NEAR(std::abs(c.point_a.y()), 0.2, 1e-12);
    EXPECT_NEAR(c.point_a.x(), 0.2, 1e-12);
    EXPECT_NEAR(c.point_a.z(), 0.1, 1e-12);
  }
  expectConsistent(w, cs);
  // penetrating by 1 cm
  w.setBodyPose(cap, at({0.2, 0, 0.1 + 0.05 - 0.01}, rpy(kPi / 2, 0, 0)));
  w.query(1, cs);
  ASSERT_EQ(cs.contacts.size(), 2u);
  for (const auto& c : cs.contacts) EXPECT_NEAR(c.distance, -0.01, 1e-12);
  expectConsistent(w, cs);
  // upright beyond the edge x = 0.5: lower sphere centre at (0.53, 0, 0.14), radius 0.02
  // → distance 0.05 − 0.02 = 0.03 to the edge point (0.5, 0, 0.1), normal (0.6, 0, 0.8)
  w.setBodyPose(cap, at({5, 5, 5}));
  const int thin = w.addBody("thin", {{Shape::capsule(0.02, 0.3), SE3()}}, at({0.53, 0, 0.14 + 0.15}),
                             BodyKind::kMovable);
  w.query(2, cs);
  ASSERT_EQ(cs.contacts.size(), 1u);
  const Contact& c = cs.contacts[0];
  EXPECT_EQ(c.body_b, thin);
  EXPECT_NEAR(c.distance, 0.03, 1e-10);
  EXPECT_TRUE(c.normal.isApprox(Vector3(0.6, 0, 0.8), 1e-9));
  EXPECT_TRUE(c.point_a.isApprox(Vector3(0.5, 0, 0.1), 1e-9));
  EXPECT_TRUE(c.point_b.isApprox(Vector3(0, 0, -0.15) - 0.02 * Vector3(0.6, 0, 0.8), 1e-9));
}

TEST(CollisionWorld, SphereMeshFaceAndCorner) {
  WorldOptions o;
  o.activation_distance = 0.05;
  CollisionWorld w(o);
  auto mesh = std::make_shared<const TriangleMesh>(test::boxMesh(0.5));
  const SE3 pose = at({1, 0, 0}, rpy(0, 0, kPi / 2));  // a quarter turn: same cube, other frame
  const int m = w.addBody("mesh", {{Shape::fromMesh(mesh), SE3()}}, pose, BodyKind::kStatic);
  const int ball = w.addBody("ball", {{Shape::sphere(0.1), SE3()}}, at({1.1, 0.05, 0.5 + 0.1 + 0.03}),
                             BodyKind::kMovable);
  ContactSet cs;
  w.query(0, cs);
  ASSERT_EQ(cs.contacts.size(), 1u);
  const Contact& c = cs.contacts[0];
  EXPECT_EQ(c.body_a, m);
  EXPECT_EQ(c.body_b, ball);
  EXPECT_NEAR(c.distance, 0.03, 1e-12);
  EXPECT_TRUE(c.normal.isApprox(Vector3::UnitZ(), 1e-12));
  EXPECT_TRUE(c.point_a.isApprox(pose.actInv(Vector3(1.1, 0.05, 0.5)), 1e-12));
  EXPECT_TRUE(c.point_b.isApprox(Vector3(0, 0, -0.1), 1e-12));
  EXPECT_GE(c.feature, 0);
  EXPECT_LT(c.feature, 12);
  // a small sphere near the corner (1.5, 0.5, 0.5) on the diagonal: d = √3·0.02 − 0.01
  w.setBodyPose(ball, at({3, -3, 3}));
  w.addBody("small", {{Shape::sphere(0.01), SE3()}}, at(Vector3(1.5, 0.5, 0.5) + 0.02 * Vector3(1, 1, 1)),
            BodyKind::kMovable);
  w.query(1, cs);
  ASSERT_EQ(cs.contacts.size(), 1u);
  EXPECT_NEAR(cs.contacts[0].distance, std::sqrt(3.0) * 0.02 - 0.01, 1e-12);
  EXPECT_TRUE(cs.contacts[0].normal.isApprox(Vector3(1, 1, 1).normalized(), 1e-12));
  EXPECT_TRUE(worldA(w, cs.contacts[0]).isApprox(Vector3(1.5, 0.5, 0.5), 1e-12));
  expectConsistent(w, cs);
}

TEST(CollisionWorld, CapsuleLyingOnMeshTwoPoints) {
  WorldOptions o;
  o.activation_distance = 0.02;
  CollisionWorld w(o);
  auto mesh = std::make_shared<const TriangleMesh>(test::boxMesh(0.5));
  w.addBody("mesh", {{Shape::fromMesh(mesh), SE3()}}, SE3(), BodyKind::kStatic);
  w.addBody("cap", {{Shape::capsule(0.05, 0.4), SE3()}}, at({0.1, 0.1, 0.5 + 0.05 + 0.01}, rotY(kPi / 2)),
            BodyKind::kMovable);
  ContactSet cs;
  w.query(0, cs);
  ASSERT_GE(cs.contacts.size(), 2u);
  ASSERT_LE(cs.contacts.size(), 4u);
  double xmin = 1e9, xmax = -1e9;
  for (const auto& c : cs.contacts) {
    EXPECT_NEAR(c.distance, 0.01, 1e-12);
    EXPECT_TRUE(c.normal.isApprox(Vector3::UnitZ(), 1e-12));
    xmin = std::min(xmin, worldA(w, c).x());
    xmax = std::max(xmax, worldA(w, c).x());
  }
  EXPECT_NEAR(xmin, -0.1, 1e-12);
  EXPECT_NEAR(xmax, 0.3, 1e-12);
  expectConsistent(w, cs);
}

TEST(CollisionWorld, BoxRestingOnPlaneFourCorners) {
  CollisionWorld w = floorWorld(0.02);
  const int box = w.addBody("box", {{Shape::box({0.4, 0.3, 0.2}), SE3()}}, at({1, 2, 0.105}, rpy(0, 0, 0.3)),
                            BodyKind::kMovable);
  ContactSet cs;
  w.query(0, cs);
  ASSERT_EQ(cs.contacts.size(), 4u);
  std::set<std::pair<int, int>> corners;
  for (const auto& c : cs.contacts) {
    EXPECT_EQ(c.body_b, box);
    EXPECT_NEAR(c.distance, 0.005, 1e-12);
    EXPECT_TRUE(c.normal.isApprox(Vector3::UnitZ()));
    EXPECT_NEAR(std::abs(c.point_b.x()), 0.2, 1e-12);
    EXPECT_NEAR(std::abs(c.point_b.y()), 0.15, 1e-12);
    EXPECT_NEAR(c.point_b.z(), -0.1, 1e-12);
    corners.insert({c.point_b.x() > 0, c.point_b.y() > 0});
  }
  EXPECT_EQ(corners.size(), 4u);
  expectConsistent(w, cs);
}

TEST(CollisionWorld, BoxOnTableBoxFourCorners) {
  WorldOptions o;
  o.activation_distance = 0.02;
  CollisionWorld w(o);
  w.addBody("table", {{Shape::box({1.2, 0.8, 0.04}), at({0, 0, 0.73})}}, SE3(), BodyKind::kStatic);
  const int box = w.addBody("box", {{Shape::box({0.2, 0.2, 0.1}), SE3()}}, at({0.1, 0.1, 0.75 + 0.05 + 0.004}),
                            BodyKind::kMovable);
  ContactSet cs;
  w.query(0, cs);
  ASSERT_EQ(cs.contacts.size(), 4u);
  for (const auto& c : cs.contacts) {
    EXPECT_EQ(c.body_b, box);
    EXPECT_NEAR(c.distance, 0.004, 1e-6);
    EXPECT_TRUE(c.normal.isApprox(Vector3::UnitZ(), 1e-9));
    EXPECT_NEAR(std::abs(c.point_b.x()), 0.1, 1e-9);
    EXPECT_NEAR(std::abs(c.point_b.y()), 0.1, 1e-9);
  }
  expectConsistent(w, cs);
}

TEST(CollisionWorld, MarginsShiftByTwiceTheMargin) {
  auto make = [](double margin) {
    CollisionWorld w = floorWorld();
    w.setMargin(0, margin);
    w.addBody("cap", {{Shape::capsule(0.05, 0.4), SE3()}}, at({0.3, 0, 0.08}, rotY(1.4)), BodyKind::kMovable,
              margin);
    w.addBody("box", {{Shape::box({0.2, 0.2, 0.2}), SE3()}}, at({2, 0, 0.11}, rpy(0.1, 0, 0)),
              BodyKind::kMovable, margin);
    return w;
  };
  CollisionWorld w0 = make(0.0), w1 = make(0.003);
  ContactSet c0, c1;
  w0.query(0, c0);
  w1.query(0, c1);
  ASSERT_EQ(c0.contacts.size(), c1.contacts.size());
  ASSERT_GE(c0.contacts.size(), 3u);
  for (std::size_t k = 0; k < c0.contacts.size(); ++k) {
    EXPECT_NEAR(c1.contacts[k].distance, c0.contacts[k].distance - 2 * 0.003, 1e-15);
    // witness points moved onto the margin shells
    EXPECT_TRUE((worldA(w1, c1.contacts[k]) - worldA(w0, c0.contacts[k])).isApprox(0.003 * c0.contacts[k].normal));
  }
  expectConsistent(w1, c1);
  // one margin only: shift by that margin
  CollisionWorld w2 = make(0.0);
  w2.setMargin(0, 0.004);
  ContactSet c2;
  w2.query(0, c2);
  ASSERT_EQ(c0.contacts.size(), c2.contacts.size());
  for (std::size_t k = 0; k < c0.contacts.size(); ++k)
    EXPECT_NEAR(c2.contacts[k].distance, c0.contacts[k].distance - 0.004, 1e-15);
}

TEST(CollisionWorld, StandingMannequinFeetFlatFourPointsEach) {
  const auto model = mannequinModel();
  skeleton::Data data(model);
  skeleton::forwardKinematics(model, data, skeleton::standingConfiguration(model));
  CollisionWorld w = floorWorld(0.01);  // the shanks' lower ends are 2 cm above the floor
  const int m = w.addMannequin(model);
  w.updateMannequin(m, data);
  ContactSet cs;
  w.query(0, cs);
  for (const char* foot : {"mannequin0/foot_l", "mannequin0/foot_r"}) {
    const auto cf = between(w, cs, "scene/floor", foot);
    ASSERT_EQ(cf.size(), 4u) << foot;
    for (const auto& c : cf) EXPECT_NEAR(c.distance, 0.0, 1e-9);
  }
  for (const auto& c : cs.contacts)  // nothing else touches the floor
    if (c.body_a == 0) {
      EXPECT_NE(w.bodyName(c.body_b).find("foot"), std::string::npos) << w.bodyName(c.body_b) << " " << c.distance;
    }
  expectConsistent(w, cs);
}

// A configuration uniform within the joint limits (±1 where a coordinate has none).
math::VectorX randomWithinLimits(const skeleton::Model& model, std::mt19937& g) {
  math::VectorX q(model.nq);
  for (int k = 0; k < model.nq; ++k) {
    const double lo = std::isfinite(model.lower_limit[k]) ? model.lower_limit[k] : -1.0;
    const double hi = std::isfinite(model.upper_limit[k]) ? model.upper_limit[k] : 1.0;
    q[k] = std::uniform_real_distribution<double>(lo, hi)(g);
  }
  return q;
}

TEST(CollisionWorld, AdjacentSegmentsNeverReportedSelfContactsAre) {
  const auto model = mannequinModel();
  skeleton::Data data(model);
  WorldOptions o;
  o.activation_distance = 0.05;
  CollisionWorld w(o);
  const int m = w.addMannequin(model);
  const std::vector<std::pair<std::string, std::string>> adjacent = {
      {"pelvis", "abdomen"}, {"abdomen", "thorax"}, {"thorax", "head"}, {"thorax", "clavicle_l"},
      {"clavicle_l", "upper_arm_l"}, {"upper_arm_l", "forearm_l"}, {"forearm_l", "hand_l"},
      {"pelvis", "thigh_l"}, {"thigh_l", "shank_l"}, {"shank_l", "foot_l"}, {"upper_arm_r", "forearm_r"},
      {"forearm_r", "hand_r"}, {"shank_r", "foot_r"}};
  for (const auto& [a, b] : adjacent)
    EXPECT_FALSE(w.pairEnabled(w.findBody("mannequin0/" + a), w.findBody("mannequin0/" + b))) << a << " " << b;
  std::mt19937 g(3);
  int self_contacts = 0;
  ContactSet cs;
  for (int trial = 0; trial < 200; ++trial) {
    skeleton::forwardKinematics(model, data, randomWithinLimits(model, g));
    w.updateMannequin(m, data);
    w.query(trial, cs);
    for (const auto& c : cs.contacts) {
      const std::string a = w.bodyName(c.body_a).substr(11), b = w.bodyName(c.body_b).substr(11);
      for (const auto& [x, y] : adjacent) EXPECT_FALSE((a == x && b == y) || (a == y && b == x)) << a << " " << b;
      ++self_contacts;
    }
    expectConsistent(w, cs);
  }
  EXPECT_GT(self_contacts, 50);  // self-collision is on and does fire
}

// Without self collision, one mannequin's segments are not collided with each other (the moving
// bodies' tree is then not collided with itself at all); a movable body added later is (the query
// after it rebuilds and collides the moving bodies again).
TEST(CollisionWorld, WithoutSelfCollisionNoSelfContactsAndAMovableBodyAddedLaterIsSeen) {
  const auto model = mannequinModel();
  skeleton::Data data(model);
  WorldOptions o;
  o.activation_distance = 0.05;
  CollisionWorld w(o);
  MannequinOptions mo;
  mo.self_collision = false;
  const int m = w.addMannequin(model, mo);
  std::mt19937 g(3);
  ContactSet cs;
  for (int trial = 0; trial < 50; ++trial) {  // the poses that gave > 50 self contacts with it on
    skeleton::forwardKinematics(model, data, randomWithinLimits(model, g));
    w.updateMannequin(m, data);
    w.query(trial, cs);
    EXPECT_TRUE(cs.contacts.empty()) << "trial " << trial << ": " << cs.contacts.size() << " self contacts";
  }
  // a movable box around the right hand: hand–box contacts
  skeleton::forwardKinematics(model, data, skeleton::standingConfiguration(model));
  w.updateMannequin(m, data);
  const int hand = w.findBody("mannequin0/hand_r");
  const math::Vector3 centre = w.bodyPose(hand).p;
  const int box = w.addBody("box", {{Shape::box(math::Vector3(0.3, 0.3, 0.3)), SE3()}}, at(centre), BodyKind::kMovable);
  w.query(100, cs);
  int hand_box = 0;
  for (const auto& c : cs.contacts) {
    EXPECT_TRUE(c.body_a == box || c.body_b == box) << w.bodyName(c.body_a) << " " << w.bodyName(c.body_b);
    if ((c.body_a == hand && c.body_b == box) || (c.body_a == box && c.body_b == hand)) ++hand_box;
  }
  EXPECT_GT(hand_box, 0);
  expectConsistent(w, cs);
}

TEST(CollisionWorld, TwoMannequinsCollide) {
  const auto model = mannequinModel();
  skeleton::Data d0(model), d1(model);
  auto q = skeleton::standingConfiguration(model);
  skeleton::forwardKinematics(model, d0, q);
  q[0] += 0.25;  // the second one 25 cm ahead, turned around: they overlap
  q[5] = kPi;
  skeleton::forwardKinematics(model, d1, q);
  CollisionWorld w = floorWorld(0.02);
  const int a = w.addMannequin(model);
  const int b = w.addMannequin(model);
  EXPECT_EQ(w.mannequinCount(), 2);
  w.updateMannequin(a, d0);
  w.updateMannequin(b, d1);
  ContactSet cs;
  w.query(0, cs);
  int cross = 0;
  for (const auto& c : cs.contacts)
    if (w.bodyName(c.body_a).rfind("mannequin0/", 0) == 0 && w.bodyName(c.body_b).rfind("mannequin1/", 0) == 0)
      ++cross;
  EXPECT_GT(cross, 0);
  expectConsistent(w, cs);
}

// A mannequin that is not placed (sim::World: not yet calibrated) pairs only with the static bodies
// and itself. Two mannequins built at the same standing pose (coincident segments) and a movable box
// through both their right hands: with the second one not placed, it keeps its feet's floor contacts
// and touches neither the first one nor the box; placed again, it touches both.
TEST(CollisionWorld, AMannequinNotPlacedTouchesOnlyStaticBodiesAndItself) {
  const auto model = mannequinModel();
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, skeleton::standingConfiguration(model));
  CollisionWorld w = floorWorld(0.02);
  const int a = w.addMannequin(model);
  const int b = w.addMannequin(model);
  w.updateMannequin(a, d);
  w.updateMannequin(b, d);
  const int hand = model.frameIndex("hand_r");
  w.addBody("box", {{Shape::box({0.1, 0.1, 0.1}), SE3()}}, SE3(math::Matrix3::Identity(), d.oMf[static_cast<std::size_t>(hand)].p),
            BodyKind::kMovable);
  EXPECT_TRUE(w.mannequinPlaced(b));
  w.setMannequinPlaced(b, false);
  EXPECT_FALSE(w.mannequinPlaced(b));
  const auto count = [&](const ContactSet& cs, const std::string& pa, const std::string& pb) {
    int n = 0;
    for (const auto& c : cs.contacts) {
      const std::string& x = w.bodyName(c.body_a);
      const std::string& y = w.bodyName(c.body_b);
      n += (x.rfind(pa, 0) == 0 && y.rfind(pb, 0) == 0) || (x.rfind(pb, 0) == 0 && y.rfind(pa, 0) == 0);
    }
    return n;
  };
  ContactSet cs;
  w.query(0, cs);
  EXPECT_GT(count(cs, "scene/floor", "mannequin1/"), 0) << "the feet of the mannequin not placed stand on the floor";
  EXPECT_EQ(count(cs, "mannequin0/", "mannequin1/"), 0);
  EXPECT_EQ(count(cs, "box", "mannequin1/"), 0);
  EXPECT_GT(count(cs, "box", "mannequin0/"), 0);
  EXPECT_GT(count(cs, "scene/floor", "mannequin0/"), 0);
  expectConsistent(w, cs);
  w.setMannequinPlaced(b, true);
  w.query(1, cs);
  // coincident segments: FCL may give up on some pairs (counted, no contact); the others touch
  EXPECT_GT(count(cs, "mannequin0/", "mannequin1/"), 0);
  EXPECT_GT(count(cs, "box", "mannequin1/"), 0);
  std::printf("placed again: %d broad-phase pairs, %d failed narrow phases\n", cs.stats.broadphase_pairs, cs.stats.failed_pairs);
  EXPECT_THROW(w.setMannequinPlaced(2, false), std::invalid_argument);
  EXPECT_THROW((void)w.mannequinPlaced(-1), std::invalid_argument);
}

TEST(CollisionWorld, DeterministicWhateverTheHistory) {
  const auto model = mannequinModel();
  skeleton::Data data(model);
  auto build = [&] {
    CollisionWorld w = floorWorld(0.05);
    w.addBody("scene/table", {{Shape::box({1.2, 0.8, 0.04}), at({0.5, 0, 0.73})}}, SE3(), BodyKind::kStatic);
    w.addMannequin(model);
    w.addBody("scene/ball", {{Shape::sphere(0.1), SE3()}}, at({0.5, 0, 0.85}), BodyKind::kMovable);
    return w;
  };
  CollisionWorld w1 = build(), w2 = build();
  const auto q0 = skeleton::standingConfiguration(model);
  std::mt19937 g(11);
  std::normal_distribution<double> n(0.0, 0.4);
  ContactSet c1, c2;
  for (int step = 0; step < 30; ++step) {
    math::VectorX q = q0;
    for (int k = 6; k < model.nq; ++k) q[k] += n(g);
    skeleton::forwardKinematics(model, data, q);
    w1.updateMannequin(0, data);
    w2.updateMannequin(0, data);
    if (step % 3 == 0) {  // w2 makes a detour (other tree shapes) before coming back
      w2.setBodyPose(w2.findBody("scene/ball"), at({9, 9, 9}));
      w2.query(step, c2);
      w2.setBodyPose(w2.findBody("scene/ball"), at({0.5, 0, 0.85}));
    }
    w1.query(step, c1);
    w2.query(step, c2);
    ASSERT_EQ(c1.contacts.size(), c2.contacts.size());
    for (std::size_t k = 0; k < c1.contacts.size(); ++k) {
      const Contact& a = c1.contacts[k];
      const Contact& b = c2.contacts[k];
      EXPECT_EQ(a.body_a, b.body_a);
      EXPECT_EQ(a.body_b, b.body_b);
      EXPECT_EQ(a.feature, b.feature);
      EXPECT_EQ(std::memcmp(&a.distance, &b.distance, sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(a.point_a.data(), b.point_a.data(), 3 * sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(a.point_b.data(), b.point_b.data(), 3 * sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(a.normal.data(), b.normal.data(), 3 * sizeof(double)), 0);
      if (k > 0) {  // sorted
        const Contact& p = c1.contacts[k - 1];
        EXPECT_TRUE(std::tie(p.body_a, p.body_b, p.shape_a, p.shape_b) <=
                    std::tie(a.body_a, a.body_b, a.shape_a, a.shape_b));
      }
    }
  }
}

TEST(CollisionWorld, BadArgumentsThrowClearly) {
  CollisionWorld w = floorWorld();
  EXPECT_THROW(w.setBodyPose(0, SE3()), std::invalid_argument);  // static
  const int b = w.addBody("b", {{Shape::sphere(0.1), SE3()}}, SE3(), BodyKind::kMovable);
  SE3 bad;
  bad.p.x() = std::nan("");
  EXPECT_THROW(w.setBodyPose(b, bad), std::invalid_argument);
  EXPECT_THROW(w.setBodyPose(99, SE3()), std::invalid_argument);
  EXPECT_THROW(w.addBody("b", {{Shape::sphere(0.1), SE3()}}, SE3(), BodyKind::kMovable), std::invalid_argument);
  EXPECT_THROW(w.setMargin(b, -0.1), std::invalid_argument);
  EXPECT_THROW(Shape::sphere(-0.1), std::invalid_argument);
  EXPECT_THROW(Shape::capsule(0.1, std::nan("")), std::invalid_argument);
  EXPECT_THROW(Shape::box({0.1, 0.0, 0.1}), std::invalid_argument);
  const auto model = mannequinModel();
  MannequinOptions o;
  o.exclude_pairs = {{"hand_l", "tail"}};
  try {
    w.addMannequin(model, o);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'tail'"), std::string::npos);
  }
  skeleton::Data data(model);
  EXPECT_THROW(w.updateMannequin(5, data), std::invalid_argument);
}

// Two identical boxes at the same pose (1 nm apart): libccd's EPA gave up on this degenerate overlap (the
// pair used to be counted as failed); the separating-axis test the narrow phase now uses for overlaps
// gives the penetration: the boxes must move apart by their smallest width (0.0708 m) plus both margins.
TEST(CollisionWorld, CoincidentBoxesGetTheirPenetrationAndTheQueryGoesOn) {
  CollisionWorld w = floorWorld(0.02);
  const double width = 0.070778059122916431312;
  const Shape box = Shape::box({width, width, 0.33110178112176769094});
  const math::Matrix3 R = rpy(0.1, 0.2, 0.3);
  const int a = w.addBody("a", {{box, SE3()}}, SE3(R, Vector3(0, 0, 0.5)), BodyKind::kMovable, 0.005);
  const int b = w.addBody("b", {{box, SE3()}}, SE3(R, Vector3(1e-9, 0, 0.5)), BodyKind::kMovable, 0.005);
  const int c = w.addBody("c", {{Shape::box({0.2, 0.2, 0.2}), SE3()}}, SE3(math::Matrix3::Identity(), Vector3(2, 0, 0.105)),
                          BodyKind::kMovable);
  ContactSet cs;
  ASSERT_NO_THROW(w.query(0, cs));
  EXPECT_EQ(cs.stats.failed_pairs, 0);
  int floor_c = 0;
  double deepest = 0;
  for (const auto& k : cs.contacts) {
    if ((k.body_a == a && k.body_b == b) || (k.body_a == b && k.body_b == a)) deepest = std::min(deepest, k.distance);
    floor_c += k.body_b == c && w.bodyName(k.body_a) == "scene/floor";
  }
  EXPECT_NEAR(deepest, -(width + 0.01), 1e-3);
  EXPECT_EQ(floor_c, 4);
  expectConsistent(w, cs);
}

// Two crossed cylinders (r = 0.1 m, 1 m long, along z and along x) whose sides overlap by 5 cm: the contact
// is where they cross — depth 5 cm, normal along y, the witness points on each side at x = z = 0 — not at
// an end of either axis (every point of an axis perpendicular to the normal is as deep).
TEST(CollisionWorld, CrossedCylindersOverlappingTouchWhereTheyCross) {
  WorldOptions o;
  o.activation_distance = 0.02;
  CollisionWorld w(o);
  const int a = w.addBody("a", {{Shape::cylinder(0.1, 1.0), SE3()}}, SE3(), BodyKind::kMovable);
  const int b = w.addBody("b", {{Shape::cylinder(0.1, 1.0), SE3()}}, SE3(rotY(kPi / 2), Vector3(0, 0.15, 0)), BodyKind::kMovable);
  ContactSet cs;
  ASSERT_NO_THROW(w.query(0, cs));
  EXPECT_EQ(cs.stats.failed_pairs, 0);
  ASSERT_EQ(cs.contacts.size(), 1u);
  const Contact& c = cs.contacts[0];
  ASSERT_EQ(c.body_a, a);
  ASSERT_EQ(c.body_b, b);
  EXPECT_NEAR(c.distance, -0.05, 1e-9);
  EXPECT_NEAR(c.normal.y(), 1.0, 1e-9);
  const Vector3 pa = w.bodyPose(a).act(c.point_a), pb = w.bodyPose(b).act(c.point_b);
  EXPECT_LT((pa - Vector3(0, 0.1, 0)).norm(), 1e-9) << pa.transpose();
  EXPECT_LT((pb - Vector3(0, 0.05, 0)).norm(), 1e-9) << pb.transpose();
  expectConsistent(w, cs);
}

// A thin cylinder (a drill bit, r = 4 mm) pushed into a wall box along the wall's normal, at several
// depths and tilts: each overlap gives a contact whose depth is the tip's (to the tilt's first order) and
// whose normal is the wall's. libccd's EPA aborted the process (an assertion in the Debian build of FCL
// 0.7, FCL issue #322) on such overlaps.
TEST(CollisionWorld, ACylinderPushedIntoABoxGetsItsDepthWithoutAborting) {
  for (const double tilt_deg : {0.0, 3.0, 10.0})
    for (const double depth : {0.0005, 0.002, 0.01, 0.03, 0.05}) {
      CollisionWorld w = floorWorld(0.02);
      w.addBody("wall", {{Shape::box({0.1, 3.0, 2.5}), SE3()}}, SE3(math::Matrix3::Identity(), Vector3(0.65, 0, 1.25)),
                BodyKind::kStatic);
      // the cylinder's axis along +x (its z turned by 90° about y), tilted about z; its tip `depth` past x = 0.6
      const math::Matrix3 R = rpy(0, 0, tilt_deg * kPi / 180.0) * rotY(kPi / 2);
      const Vector3 axis = R.col(2);
      const Vector3 center = Vector3(0.6 + depth, -0.2, 1.2) - 0.06 * axis;
      w.addBody("bit", {{Shape::cylinder(0.004, 0.12), SE3()}}, SE3(R, center), BodyKind::kMovable);
      ContactSet cs;
      ASSERT_NO_THROW(w.query(0, cs));
      EXPECT_EQ(cs.stats.failed_pairs, 0);
      const auto c = between(w, cs, "wall", "bit");
      ASSERT_FALSE(c.empty()) << "depth " << depth << " tilt " << tilt_deg;
      double deepest = 0;
      for (const auto& k : c) {
        deepest = std::min(deepest, k.distance);
        EXPECT_GT(-k.normal.x(), 0.99) << "the normal from the wall to the bit is −x";
      }
      // the deepest rim point: depth − r·sin(tilt) ≤ reach ≤ depth + r·sin(tilt)
      const double slack = 0.004 * std::sin(tilt_deg * kPi / 180.0) + 1e-4;
      EXPECT_NEAR(-deepest, depth, slack) << "depth " << depth << " tilt " << tilt_deg;
      expectConsistent(w, cs);
    }
}
