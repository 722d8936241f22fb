// The per-step stages of rigid objects and their producers allocate nothing (malloc counted).
#include <gtest/gtest.h>

#include "mannequin/sim/rigid_object.hpp"
#include "../common/alloc_counter.hpp"

namespace {

using mannequin::math::Vector3;
namespace cs = mannequin::constraints;
namespace sim = mannequin::sim;

TEST(RigidObjectAlloc, StagesAndProducersAllocateNothing) {
  sim::RigidObjectSpec free_spec;
  free_spec.name = "ball";
  free_spec.pose.p = Vector3(0, 0, 1);
  sim::RigidObjectSpec hinge_spec;
  hinge_spec.name = "lever";
  hinge_spec.pose.p = Vector3(0, 0, 0.2);
  hinge_spec.hinge = mannequin::collision::HingeSpec{Vector3::UnitY(), Vector3::Zero(), -0.1, 0.1};
  sim::RigidObjectSpec hand_spec;
  hand_spec.name = "hand";
  hand_spec.pose.p = Vector3(0, 0, 1.1);
  sim::RigidObject ball(free_spec), lever(hinge_spec), hand(hand_spec);
  cs::RowSet rows({6, 1, 6}, 32, 8, 4);
  sim::HingeLimitRows limits({{&lever, 1}});
  sim::GraspRows grasps({&ball, &lever}, {0, 1}, 6);
  const Eigen::VectorXd g6 = Eigen::VectorXd::Constant(6, 0.1), g1 = Eigen::VectorXd::Constant(1, 0.1);
  const Vector3 gravity(0, 0, -9.81);
  int handle = grasps.grasp({2, &hand, 0}, 0);
  ASSERT_GE(handle, 0);
  const auto step = [&] {
    for (sim::RigidObject* o : {&ball, &lever, &hand}) o->computeFreeMotion(gravity, 0.001);
    lever.addForce(Vector3(0, 0, 0.3), Vector3(1, 0, 0));
    rows.clear();
    limits.addRows(0, 0.001, rows);
    grasps.addRows(1, 0.001, rows);
    grasps.solved(1, rows);
    ball.applyConstraintForce(g6);
    hand.applyConstraintForce(g6);
    lever.applyConstraintForce(g1);
    for (sim::RigidObject* o : {&ball, &lever, &hand}) o->integrate(0.001);
    grasps.release(handle);
    handle = grasps.grasp({2, &hand, 0}, 0);
  };
  step();  // warm-up
  const long n = countAllocations([&] {
    for (int k = 0; k < 100; ++k) step();
  });
  if (n < 0) GTEST_SKIP() << "allocations not counted under AddressSanitizer";
  EXPECT_EQ(n, 0);
  EXPECT_EQ(rows.size(), 6 + 2);  // the grasp's six rows and both limits of the lever (±0.1 rad, within 0.2)
}

}  // namespace
