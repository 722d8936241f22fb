// First-order simulation (thesis 2.2.1.1–2.2.1.2): Euler on a damped spring (2.6–2.11), the
// stability check, and configuration-space integration on the manifold (Annex C).
#include <gtest/gtest.h>

#include <random>

#include "common.hpp"

using namespace mannequin;
using namespace mannequin::control;
using namespace mannequin::control::testing;

TEST(FirstOrder, EulerSpringIsGeometricWithRatioOneMinusKdtOverB) {
  // b ẋ = −k x (2.6), explicit Euler (2.7): x_{k+1} = (1 − kδt/b) x_k (2.9)
  const double b = 2.0, dt = 0.01;
  for (double k : {50.0, 150.0, 250.0, 450.0}) {
    const double ratio = eulerStabilityRatio(k, b, dt);
    double x = 1.0;
    for (int i = 0; i < 50; ++i) x += dt * (-k * x / b);
    EXPECT_NEAR(x, std::pow(1.0 - ratio, 50), 1e-12 * (1 + std::abs(x)));
    // (2.11): converges iff 0 < ratio < 2
    if (ratio < 2) EXPECT_LT(std::abs(x), 1.0) << "k=" << k;
    else EXPECT_GT(std::abs(x), 1.0) << "k=" << k;
  }
  EXPECT_DOUBLE_EQ(eulerStabilityRatio(200, 2, 0.01), 1.0);
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
