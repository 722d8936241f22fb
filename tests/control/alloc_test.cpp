// The control step allocates nothing after construction: the three stages with a constraint force,
// two priority levels, the internal control, an enabled virtual mechanism and the joint coupling
// (set again inside the loop). Allocations are counted by
// tests/common/alloc_counter.hpp (malloc interposed; under AddressSanitizer its allocator hook). With
// -DMANNEQUIN_CHECK_RUNTIME_MALLOC=ON the loop also runs under NoEigenMalloc: an Eigen allocation
// asserts at the line that makes it.
#include <gtest/gtest.h>

#include <cstddef>

#include "common.hpp"
#include "../common/alloc_counter.hpp"
#include "../common/no_eigen_malloc.hpp"

using namespace mannequin;
using namespace mannequin::control;
using namespace mannequin::control::testing;

TEST(ControlAlloc, StepAllocatesNothing) {
  if (!allocationsCountable()) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  for (ProjectorMethod method : {ProjectorMethod::kLdlt, ProjectorMethod::kSvd}) {
    ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
    c.projector = method;
    Controller ctl(male50(), c);
    const int h = ctl.frameIndex("hand_r");
    MechanismConfig m;
    m.spec.type = MechanismType::kSlidingPivot;
    m.spec.base = ctl.frame(h).pose;
    m.stiffness = gains(1000, 10000);
    m.damping = gains(10, 100);
    m.enabled = true;
    ctl.attachMechanism(h, m);
    VectorX gamma_c = VectorX::Zero(ctl.model().nv);
    gamma_c(2) = 10.0;
    SE3 target = ctl.frame(ctl.frameIndex("hand_l")).pose;
    // the joint coupling on (sim::World sets it again every balance period)
    VectorX q_j = ctl.q();
    q_j.tail(ctl.model().nq - 6).array() += 0.05;
    const VectorX k_j = VectorX::Constant(ctl.model().nv, 50.0), b_j = VectorX::Constant(ctl.model().nv, 0.5);
    ctl.setJointCoupling(q_j, k_j, b_j);
    ctl.step();  // warm-up
    const long allocations = countAllocations([&] {
      const NoEigenMalloc no_eigen_malloc;
      for (int i = 0; i < 50; ++i) {
        target.p.x() += 1e-4;
        ctl.setTarget(ctl.frameIndex("hand_l"), target);
        ctl.computeFreeMotion();
        ctl.applyConstraintForce(gamma_c);
        ctl.integrate();
        ctl.setJointCoupling(q_j, k_j, b_j);
        ctl.step();
      }
    });
    EXPECT_EQ(allocations, 0) << toString(method);
    EXPECT_GT(ctl.jointCouplingTorque().cwiseAbs().maxCoeff(), 0.0) << "the coupling was on";
  }
}
