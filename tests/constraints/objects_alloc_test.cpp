// The per-step stages of rigid objects and their producers allocate nothing (malloc counted); and the
// whole World step with physics (collision query, controller, contacts, joint limits, objects, grasps,
// balance distance, one LCP, integration) allocates nothing after warm-up.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mannequin/collision/scene.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/sim/object_guides.hpp"
#include "mannequin/constraints/objects.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "../common/alloc_counter.hpp"

namespace {

using mannequin::math::Vector3;
namespace cs = mannequin::constraints;
namespace sim = mannequin::sim;

TEST(RigidObjectAlloc, StagesAndProducersAllocateNothing) {
  cs::RigidObjectSpec free_spec;
  free_spec.name = "ball";
  free_spec.pose.p = Vector3(0, 0, 1);
  cs::RigidObjectSpec hinge_spec;
  hinge_spec.name = "lever";
  hinge_spec.pose.p = Vector3(0, 0, 0.2);
  hinge_spec.hinge = mannequin::collision::HingeSpec{Vector3::UnitY(), Vector3::Zero(), -0.1, 0.1};
  cs::RigidObjectSpec hand_spec;
  hand_spec.name = "hand";
  hand_spec.pose.p = Vector3(0, 0, 1.1);
  cs::RigidObject ball(free_spec), lever(hinge_spec), hand(hand_spec);
  cs::RowSet rows({6, 1, 6}, 32, 8, 4);
  cs::HingeLimitRows limits({{&lever, 1}});
  cs::GraspRows grasps({&ball, &lever}, {0, 1}, 6);
  // a guide on the "hand" object: a sliding pivot with stops 1 cm either side (two tilt rows, two position
  // rows, both stops within its 0.5 m activation: the unconstrained test motion drifts a few cm)
  sim::GuideRows guides({&ball, &lever, &hand}, {0, 1, 2}, 0.5);
  mannequin::control::MechanismSpec pivot;
  pivot.type = mannequin::control::MechanismType::kSlidingPivot;
  pivot.base = hand.pose();
  pivot.lower = Eigen::Vector2d(-0.01, -std::numeric_limits<double>::infinity());
  pivot.upper = Eigen::Vector2d(0.01, std::numeric_limits<double>::infinity());
  guides.attach(2, pivot);
  double guide_error = 0;
  const Eigen::VectorXd g6 = Eigen::VectorXd::Constant(6, 0.1), g1 = Eigen::VectorXd::Constant(1, 0.1);
  const Vector3 gravity(0, 0, -9.81);
  int handle = grasps.grasp({2, &hand, 0}, 0);
  ASSERT_GE(handle, 0);
  const auto step = [&] {
    for (cs::RigidObject* o : {&ball, &lever, &hand}) o->computeFreeMotion(gravity, 0.001);
    lever.addForce(Vector3(0, 0, 0.3), Vector3(1, 0, 0));
    rows.clear();
    limits.addRows(0, 0.001, rows);
    grasps.addRows(1, 0.001, rows);
    grasps.solved(1, rows);
    guides.addRows(2, 0.001, rows);
    guides.solved(2, rows);
    guide_error += guides.positionError(2) + guides.angleError(2) + guides.coordinates(2)(0);
    ball.applyConstraintForce(g6);
    hand.applyConstraintForce(g6);
    lever.applyConstraintForce(g1);
    for (cs::RigidObject* o : {&ball, &lever, &hand}) o->integrate(0.001);
    grasps.release(handle);
    handle = grasps.grasp({2, &hand, 0}, 0);
  };
  step();  // warm-up
  const long n = countAllocations([&] {
    for (int k = 0; k < 100; ++k) step();
  });
  if (n < 0) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  EXPECT_EQ(n, 0);
  // the grasp's six rows, both limits of the lever (±0.1 rad, within 0.2), the guide's two position, two tilt
  // and two stop rows
  EXPECT_EQ(rows.size(), 6 + 2 + 6);
  EXPECT_TRUE(std::isfinite(guide_error));
}

TEST(WorldAlloc, APhysicsStepAllocatesNothingAfterWarmUp) {
  namespace sk = mannequin::skeleton;
  sim::MannequinSetup m;
  m.name = "operator";
  m.model = sk::buildMannequin(sk::loadMannequinSpec("configs/mannequins/male_50th.yaml"));
  const char* bodies[] = {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r"};
  for (const char* b : bodies) m.frames.push_back({b, b});
  m.controller = mannequin::control::loadControllerConfig("configs/control/mocap.yaml");
  sim::SimConfig cfg;
  cfg.physics.enabled = true;
  // floor, a table top, a ball resting on it and a weight on the floor that the left hand holds: plane–box
  // (feet), box–sphere (ball on the top), sphere–plane and capsule pairs, all of our own narrow phase. Box–box and cylinder
  // pairs go to FCL's GJK, which allocates its ccd objects on every call (docs/collision.md): not here.
  cfg.physics.scene = mannequin::collision::parseScene(
      "bodies:\n"
      "  - name: floor\n    shape: {type: plane, normal: [0, 0, 1], offset: 0}\n"
      "  - name: table\n    pose: {position: [0.8, 0, 0.73]}\n    shape: {type: box, size: [1.0, 0.8, 0.04]}\n"
      "  - name: ball\n    movable: true\n    pose: {position: [0.8, 0.2, 0.86]}\n    mass: 0.45\n"
      "    inertia: [0.002178, 0.002178, 0.002178]\n    shape: {type: sphere, radius: 0.11}\n"
      "  - name: crate\n    movable: true\n    pose: {position: [0.5, -0.5, 0.12]}\n    mass: 2\n"
      "    shape: {type: sphere, radius: 0.12}\n",
      "alloc-scene.yaml");
  std::vector<sim::MannequinSetup> setups;
  setups.push_back(std::move(m));
  sim::World w(std::move(setups), cfg);
  // the actor stands where the model stands (markers on its frames)
  sk::Data d(w.model(0));
  sk::forwardKinematics(w.model(0), d, sk::standingConfiguration(w.model(0)));
  mannequin::mocap::Frame f;
  for (const char* b : bodies) f.bodies.push_back({b, d.oMf[static_cast<std::size_t>(w.model(0).frameIndex(b))], true});
  w.addMocap(f);
  w.anchor(0);
  ASSERT_TRUE(w.calibrated(0));
  // a grasp makes the grasp rows and the contact filter part of every step
  const int g = w.grasp(0, "hand_l", "crate");
  ASSERT_GE(g, 0);
  for (int k = 0; k < 300; ++k) ASSERT_TRUE(w.step());  // warm-up: buffers reach their sizes
  int rows = 0;
  const long n = countAllocations([&] {
    for (int k = 0; k < 300; ++k) {
      w.step();
      rows = std::max(rows, w.diagnostics().solver.rows);
    }
  });
  if (n < 0) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  EXPECT_EQ(n, 0);
  EXPECT_GT(w.diagnostics().contacts, 0);  // the feet (and the objects) are in contact: real rows
  EXPECT_GE(rows, 6);                      // at least the grasp's six
  EXPECT_EQ(w.failedSteps(), 0u);
}

}  // namespace
