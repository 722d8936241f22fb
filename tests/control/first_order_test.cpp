// First-order simulation (thesis 2.2.1.1–2.2.1.2) through the library: the controller's Euler step on
// a joint spring against the closed form (2.6–2.11), the stability check, and configuration-space
// integration on the manifold (Annex C), hand-checked per joint type and against skeleton::integrate.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "common.hpp"

using namespace mannequin;
using namespace mannequin::control;
using namespace mannequin::control::testing;

namespace {

int coordinateIndex(const skeleton::Model& model, const std::string& name) {
  const auto names = model.coordinateNames();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  ADD_FAILURE() << "no coordinate " << name;
  return 0;
}

int firstJointOfType(const skeleton::Model& model, skeleton::JointType type) {
  for (const auto& j : model.joints)
    if (j.type == type) return static_cast<int>(&j - model.joints.data());
  ADD_FAILURE() << "no joint of type " << skeleton::toString(type);
  return 0;
}

}  // namespace

TEST(FirstOrder, ControllerStepOnAJointSpringIsGeometricWithRatioOneMinusKdtOverB) {
  // b ẋ = −k x (2.6) on one joint: the internal potential of knee_l only (no frames, no gravity,
  // neutral posture, every other coordinate at its rest), b_a = b on the knee. The controller's
  // explicit Euler step (2.7) must give x_{k+1} = (1 − kδt/b) x_k (2.9): x_N = (1 − r)^N x_0 in
  // closed form, q̇ = −k x_k / b, and it converges iff r < 2 (2.11); checkStability reports r.
  const auto& model = male50();
  const int knee = coordinateIndex(model, "knee_l");
  const double b = 2.0, dt = 0.01, x0 = 0.1;
  for (double k : {50.0, 150.0, 200.0, 250.0, 450.0}) {
    ControllerConfig c = baseConfig();
    c.dt = dt;
    c.internal.posture = "neutral";
    c.internal.coordinates["knee_l"] = k;
    c.b_a.coordinates["knee_l"] = b;
    VectorX q0 = model.neutralConfiguration();
    q0(knee) = x0;
    Controller ctl(model, c, q0);
    const double r = eulerStabilityRatio(k, b, dt);
    EXPECT_DOUBLE_EQ(r, k * dt / b);
    bool reported = false;
    for (const auto& e : ctl.checkStability())
      if (e.what == "internal knee_l") {
        EXPECT_DOUBLE_EQ(e.ratio, r);
        reported = true;
      }
    EXPECT_TRUE(reported) << "checkStability has no entry 'internal knee_l'";
    double x = x0;
    for (int n = 1; n <= 50; ++n) {
      ASSERT_EQ(ctl.step(), StepStatus::kOk);
      EXPECT_NEAR(ctl.qdot()(knee), -k * x / b, 1e-12 * (1 + std::abs(k * x / b))) << "k=" << k << " n=" << n;
      x = ctl.q()(knee);
      const double closed = x0 * std::pow(1.0 - r, n);
      ASSERT_NEAR(x, closed, 1e-11 * std::max(x0, std::abs(closed))) << "k=" << k << " n=" << n;
    }
    // nothing else moves: the other coordinates sit at their rest, the root feels no torque
    VectorX rest = q0;
    rest(knee) = x;
    EXPECT_LE((ctl.q() - rest).cwiseAbs().maxCoeff(), 1e-14) << "k=" << k;
    // (2.11): converges iff 0 < r < 2 (r = 1 reaches the rest in one step: the closed form above)
    if (r < 2) EXPECT_LT(std::abs(x), x0) << "k=" << k;
    else EXPECT_GT(std::abs(x), x0) << "k=" << k;
    // a linear spring under the trapezoidal work creates nothing: the energy observer keeps α = 1
    EXPECT_EQ(ctl.alpha(), 1.0) << "k=" << k;
  }
}

TEST(FirstOrder, IntegrateInPlaceHandCheckedJoints) {
  const auto& model = male50();
  const VectorX zero = VectorX::Zero(model.nv);
  // revolute: q + v δt
  {
    const int j = firstJointOfType(model, skeleton::JointType::kRevolute);
    const int iq = model.joints[j].idx_q, iv = model.joints[j].idx_v;
    VectorX q = model.neutralConfiguration(), v = zero, out;
    q(iq) = 0.3;
    v(iv) = 2.0;
    integrateInPlace(model, q, v, 0.01, out);
    VectorX expected = q;
    expected(iq) = 0.32;
    EXPECT_LE((out - expected).cwiseAbs().maxCoeff(), 1e-15);  // and nothing else moved
  }
  // ball: rotations about one axis add; z by 90° then body x by 90° is 120° about (1, 1, 1)/√3
  // (Rz·Rx = [[0,0,1],[1,0,0],[0,1,0]], trace 0)
  {
    const int j = firstJointOfType(model, skeleton::JointType::kBall);
    const int iq = model.joints[j].idx_q, iv = model.joints[j].idx_v;
    VectorX q = model.neutralConfiguration(), v = zero, out;
    q.segment<3>(iq) = Vector3(0, 0, 0.5);
    v.segment<3>(iv) = Vector3(0, 0, 1.0);
    integrateInPlace(model, q, v, 0.1, out);
    EXPECT_LT((out.segment<3>(iq) - Vector3(0, 0, 0.6)).norm(), 1e-15);
    q.segment<3>(iq) = Vector3(0, 0, M_PI / 2);
    v.segment<3>(iv) = Vector3(M_PI / 2, 0, 0);
    integrateInPlace(model, q, v, 1.0, out);
    EXPECT_LT((out.segment<3>(iq) - Vector3::Constant(2 * M_PI / 3 / std::sqrt(3.0))).norm(), 1e-12);
  }
  // free flyer: body twist, (ω, v) order. Rotated 90° about z, a body velocity along x moves the
  // root along world y; a pure body rotation leaves the origin in place.
  {
    VectorX q = model.neutralConfiguration(), v = zero, out;
    q.segment<3>(0) = Vector3(1, 2, 3);
    q.segment<3>(3) = Vector3(0, 0, M_PI / 2);
    v.segment<3>(3) = Vector3(0.5, 0, 0);
    integrateInPlace(model, q, v, 0.2, out);
    EXPECT_LT((out.head<3>() - Vector3(1, 2.1, 3)).norm(), 1e-14);
    EXPECT_LT((out.segment<3>(3) - q.segment<3>(3)).norm(), 1e-14);
    v.setZero();
    v.segment<3>(0) = Vector3(0, 0, 0.25);
    integrateInPlace(model, q, v, 2.0, out);
    EXPECT_LT((out.head<3>() - q.head<3>()).norm(), 1e-14);
    EXPECT_LT((out.segment<3>(3) - Vector3(0, 0, M_PI / 2 + 0.5)).norm(), 1e-14);
  }
}

TEST(FirstOrder, IntegrateAndDifferenceInPlaceMatchSkeleton) {
  const auto& model = male50();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    VectorX q(model.nq), v(model.nv), out(model.nq), d(model.nv);
    for (int i = 0; i < model.nq; ++i) q(i) = 0.8 * u(rng);
    for (int i = 0; i < model.nv; ++i) v(i) = 2.0 * u(rng);
    integrateInPlace(model, q, v, 0.01, out);
    EXPECT_LT((out - skeleton::integrate(model, q, v, 0.01)).cwiseAbs().maxCoeff(), 1e-14);
    differenceInPlace(model, q, out, d);
    EXPECT_LT((d - skeleton::difference(model, q, out)).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LT((d - 0.01 * v).cwiseAbs().maxCoeff(), 1e-9);  // inverse of integrate
    // in place (aliasing)
    VectorX q2 = q;
    integrateInPlace(model, q2, v, 0.01, q2);
    EXPECT_LT((q2 - out).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(FirstOrder, RootIntegratesOnSE3CrouchGrossman) {
  // constant body twist: N Euler steps H ← H exp(V δt) give exactly H0 exp(N δt V) (Annex C)
  const auto& model = male50();
  VectorX q = model.neutralConfiguration(), v = VectorX::Zero(model.nv);
  v.head<6>() << 0.3, -0.2, 0.5, 0.4, 0.1, -0.3;
  const double dt = 0.002;
  for (int i = 0; i < 500; ++i) integrateInPlace(model, q, v, dt, q);
  const SE3 expected = math::expSE3(v.head<6>() * (500 * dt));
  EXPECT_LT((q.head<3>() - expected.p).norm(), 1e-10);
  EXPECT_LT((math::expSO3(q.segment<3>(3)) - expected.R).norm(), 1e-10);
}

TEST(FirstOrder, StabilityCheckPredictsDivergenceOfAStiffUndampedCoupling) {
  // one hand coupling; zero coupling damping and a stiffness with k·dt/b_eff > 2 diverges (2.11),
  // the same stiffness with the damping in b (2.17) converges
  const auto& model = male50();
  for (double damping : {0.0, 200.0}) {
    ControllerConfig c = baseConfig();
    c.internal.enabled = false;
    ControlFrameConfig hand = frameConfig("hand_r", 0, 0, 20000);
    hand.damping = gains(0, damping);
    c.frames = {hand};
    Controller ctl(model, c);
    double worst = 0;
    for (const auto& e : ctl.checkStability()) worst = std::max(worst, e.ratio);
    const int h = ctl.frameIndex("hand_r");
    SE3 target = ctl.frame(h).pose;
    target.p += Vector3(0.02, 0.0, 0.02);
    ctl.setTarget(h, target);
    // the prediction is local (b_eff depends on q): look at the first steps, as in (2.9)
    std::vector<double> err;
    for (int i = 0; i < 6; ++i) {
      ctl.computeFreeMotion();
      err.push_back(ctl.frame(h).positionError());
      ctl.integrate();
    }
    if (damping == 0) {
      EXPECT_GT(worst, 2.0);
      EXPECT_GT(err[5], 5 * err[0]) << "predicted unstable";
    } else {
      EXPECT_LT(worst, 1.0);
      for (int i = 1; i < 6; ++i) EXPECT_LT(err[i], err[i - 1]);
    }
  }
}
