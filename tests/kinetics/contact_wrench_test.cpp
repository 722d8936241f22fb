// A wrench shared among frictional point contacts: cases solved by hand (a table on two legs, a CoM
// outside the support, a pull, a slide), and the residual reporting what no contact can carry.
#include "mannequin/kinetics/contact_wrench.hpp"

#include <gtest/gtest.h>

using namespace mannequin;
using namespace mannequin::kinetics;

namespace {
constexpr double kMg = 700.0;

Vector6 weightAbout(const Vector3& com, const Vector3& reference) {
  // the environment must give +mg upward through the CoM: moment about the reference (c − r) × f
  const Vector3 f(0, 0, kMg);
  Vector6 w;
  w << (com - reference).cross(f), f;
  return w;
}

ContactPoint floorAt(double x, double y) {
  ContactPoint c;
  c.point = Vector3(x, y, 0);
  c.normal = Vector3::UnitZ();
  c.mu = 0.5;
  return c;
}
}  // namespace

TEST(DistributeWrench, TwoContactsUnderTheCoMShareTheWeightByTheLever) {
  // contacts at x = 0 and x = 0.4, CoM at x = 0.1 above: the lever rule gives 3/4 and 1/4 of mg
  const Vector3 com(0.1, 0, 1.0);
  const std::vector<ContactPoint> contacts{floorAt(0, 0), floorAt(0.4, 0)};
  // a line of contacts cannot resist a moment about x: keep the CoM on it (y = 0)
  const WrenchDistribution d = distributeWrench(weightAbout(com, com), com, contacts);
  ASSERT_EQ(d.status, lcp::LcpStatus::Solved);
  EXPECT_NEAR(d.forces[0].z(), 0.75 * kMg, 1e-3 * kMg);
  EXPECT_NEAR(d.forces[1].z(), 0.25 * kMg, 1e-3 * kMg);
  EXPECT_LT(d.residual_force.norm(), 1e-3 * kMg);
  EXPECT_LT(d.residual_moment.norm(), 1e-3 * kMg * 0.1);
  for (const Vector3& f : d.forces) EXPECT_LE(std::hypot(f.x(), f.y()), 0.5 * f.z() + 1e-6);
}

TEST(DistributeWrench, CoMOutsideTheSupportLeavesAResidualMoment) {
  // four contacts on the unit square around the origin, CoM 0.3 m past its +x edge: the best the floor does
  // is push at the edge; the moment mg · 0.3 about y cannot be carried
  const Vector3 com(0.8, 0, 1.0);
  const std::vector<ContactPoint> contacts{floorAt(-0.5, -0.5), floorAt(0.5, -0.5), floorAt(0.5, 0.5), floorAt(-0.5, 0.5)};
  const WrenchDistribution d = distributeWrench(weightAbout(com, com), com, contacts);
  ASSERT_EQ(d.status, lcp::LcpStatus::Solved);
  // the residual is not zero and it is what is left of the required wrench
  EXPECT_GT(d.residual_moment.norm() + 0.1 * d.residual_force.norm(), 0.05 * kMg * 0.3);
  Vector3 carried = Vector3::Zero();
  for (const Vector3& f : d.forces) carried += f;
  EXPECT_LT((carried + d.residual_force - Vector3(0, 0, kMg)).norm(), 1e-6 * kMg);
}

TEST(DistributeWrench, TheFloorCannotPull) {
  // an upward pull on the body (the wrench asks for a downward force from the floor): all residual
  const Vector3 com(0, 0, 1);
  Vector6 w;
  w << Vector3::Zero(), Vector3(0, 0, -200);
  const WrenchDistribution d = distributeWrench(w, com, {floorAt(0.1, 0.1), floorAt(-0.1, -0.1)});
  ASSERT_EQ(d.status, lcp::LcpStatus::Solved);
  for (const Vector3& f : d.forces) EXPECT_LT(f.norm(), 1e-3);
  EXPECT_NEAR(d.residual_force.z(), -200, 1e-3);
}

TEST(DistributeWrench, FrictionCarriesAsMuchAsTheConeAllows) {
  // one contact under the CoM asked for 100 N sideways with mg down, μ = 0.5: 100 ≤ 0.5 · 700 is carried;
  // 500 N sideways is not (at most μ mg = 350 N along an edge of the 8-edge cone, which reaches μ in x)
  const Vector3 com(0, 0, 0);
  ContactPoint c = floorAt(0, 0);
  Vector6 w;
  w << Vector3::Zero(), Vector3(100, 0, kMg);
  WrenchDistribution d = distributeWrench(w, com, {c});
  EXPECT_LT(d.residual_force.norm(), 1e-3 * kMg);
  EXPECT_NEAR(d.forces[0].x(), 100, 0.1);
  w << Vector3::Zero(), Vector3(500, 0, kMg);
  d = distributeWrench(w, com, {c});
  EXPECT_GT(d.residual_force.norm(), 50.0);
  EXPECT_LE(d.forces[0].x(), 0.5 * d.forces[0].z() + 1e-6);
}

TEST(DistributeWrench, NoContactLeavesEverythingResidual) {
  Vector6 w;
  w << 1, 2, 3, 4, 5, 6;
  const WrenchDistribution d = distributeWrench(w, Vector3::Zero(), {});
  EXPECT_EQ(d.residual_moment, Vector3(1, 2, 3));
  EXPECT_EQ(d.residual_force, Vector3(4, 5, 6));
}

TEST(DistributeWrench, RefusesBadContactsNamingThem) {
  Vector6 w = Vector6::Zero();
  ContactPoint bad = floorAt(0, 0);
  bad.mu = -1;
  try {
    distributeWrench(w, Vector3::Zero(), {floorAt(1, 0), bad});
    FAIL() << "a negative μ was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("contact 1"), std::string::npos) << e.what();
  }
  bad = floorAt(0, 0);
  bad.normal = Vector3::Zero();
  EXPECT_THROW(distributeWrench(w, Vector3::Zero(), {bad}), std::invalid_argument);
  bad = floorAt(0, std::nan(""));
  EXPECT_THROW(distributeWrench(w, Vector3::Zero(), {bad}), std::invalid_argument);
  w(2) = std::nan("");
  EXPECT_THROW(distributeWrench(w, Vector3::Zero(), {floorAt(0, 0)}), std::invalid_argument);
}
