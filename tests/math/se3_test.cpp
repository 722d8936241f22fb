#include "mannequin/math/se3.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

using namespace mannequin::math;

namespace {
using std::numbers::pi;

struct Rng {
  std::mt19937 g{42};
  std::normal_distribution<double> n;
  Vector3 v3() { return Vector3(n(g), n(g), n(g)); }
  Vector6 v6() {
    Vector6 v;
    v << v3(), v3();
    return v;
  }
  SE3 pose() { return expSE3(v6()); }
};
}  // namespace

TEST(SE3, ExpMatchesMatrixExponential) {
  Rng rng;
  for (int i = 0; i < 20; ++i) {
    const Vector6 V = rng.v6();
    const Matrix4 expected = hat6(V).exp();  // Eigen's Padé matrix exponential
    EXPECT_TRUE(expSE3(V).toMatrix().isApprox(expected, 1e-12));
  }
}

TEST(SE3, ExpWithZeroRotationIsPureTranslation) {
  Vector6 V;
  V << 0, 0, 0, 1, 2, 3;
  const SE3 H = expSE3(V);
  EXPECT_TRUE(H.R.isIdentity(0.0));
  EXPECT_TRUE(H.p.isApprox(Vector3(1, 2, 3), 0.0));
}

TEST(SE3, ExpMatchesThesisClosedForm) {
  // thesis 1.10: p = (1/‖ω‖²)((I − Ω)(ω ∧ v) + ω ωᵀ v). As printed in the thesis the ωωᵀv term
  // sits inside the (I − Ω) factor, where it vanishes (Ωω = ω); the pitch term belongs outside.
  Rng rng;
  for (int i = 0; i < 20; ++i) {
    const Vector3 w = rng.v3(), v = rng.v3();
    const Matrix3 Omega = expSO3(w);
    const Vector3 p = ((Matrix3::Identity() - Omega) * w.cross(v) + w * w.dot(v)) / w.squaredNorm();
    Vector6 V;
    V << w, v;
    EXPECT_TRUE(expSE3(V).p.isApprox(p, 1e-12));
    EXPECT_TRUE(expSE3(V).R.isApprox(Omega, 1e-15));
  }
}

TEST(SE3, LogInvertsExpIncludingEdgeAngles) {
  Rng rng;
  const double angles[] = {0.0, 1e-9, 1e-5, 1.0, pi - 1e-9, pi};
  for (int i = 0; i < 30; ++i) {
    const Vector3 u = rng.v3().normalized();
    const Vector3 v = rng.v3();
    for (double t : angles) {
      Vector6 V;
      V << t * u, v;
      const SE3 H = expSE3(V);
      // exp(log H) = H for every angle, including π where log has two answers
      EXPECT_TRUE(expSE3(logSE3(H)).isApprox(H, 1e-9)) << "angle " << t;
      if (t < pi - 1e-6) {
        EXPECT_LT((logSE3(H) - V).norm(), 1e-8) << "angle " << t;
      }
    }
  }
  // random poses
  for (int i = 0; i < 100; ++i) {
    const SE3 H = rng.pose();
    EXPECT_TRUE(expSE3(logSE3(H)).isApprox(H, 1e-10));
  }
}

TEST(SE3, ComposeAndInverse) {
  Rng rng;
  const SE3 A = rng.pose(), B = rng.pose();
  EXPECT_TRUE((A * B).toMatrix().isApprox(A.toMatrix() * B.toMatrix(), 1e-13));
  EXPECT_TRUE((A * A.inverse()).isApprox(SE3::Identity(), 1e-13));
  const Vector3 x = rng.v3();
  EXPECT_TRUE(A.actInv(A.act(x)).isApprox(x, 1e-13));
}

TEST(SE3, AdjointMatchesConjugation) {
  // [Ad_H V] = H [V] H⁻¹ (thesis 1.8) with Ad_H = [R 0; [p]R R] (1.9)
  Rng rng;
  for (int i = 0; i < 20; ++i) {
    const SE3 H = rng.pose();
    const Vector6 V = rng.v6();
    const Matrix4 conj = H.toMatrix() * hat6(V) * H.inverse().toMatrix();
    EXPECT_TRUE(hat6(Ad(H) * V).isApprox(conj, 1e-12));
    EXPECT_TRUE(actTwist(H, V).isApprox(Ad(H) * V, 1e-13));
    EXPECT_TRUE((AdInv(H) * Ad(H)).isApprox(Matrix6::Identity(), 1e-12));
    EXPECT_TRUE(Ad(H * H).isApprox(Ad(H) * Ad(H), 1e-12));
  }
}

TEST(SE3, SmallAdjointIsLieBracket) {
  // [[V1],[V2]] = [ad_V1 V2] (thesis 1.6) and the explicit form (1.7)
  Rng rng;
  for (int i = 0; i < 20; ++i) {
    const Vector6 V1 = rng.v6(), V2 = rng.v6();
    const Matrix4 bracket = hat6(V1) * hat6(V2) - hat6(V2) * hat6(V1);
    EXPECT_TRUE(hat6(ad(V1) * V2).isApprox(bracket, 1e-12));
    const Vector3 w1 = V1.head<3>(), v1 = V1.tail<3>(), w2 = V2.head<3>(), v2 = V2.tail<3>();
    Vector6 expected;
    expected << w1.cross(w2), w1.cross(v2) - w2.cross(v1);
    EXPECT_TRUE((ad(V1) * V2).isApprox(expected, 1e-12));
  }
}

TEST(SE3, CoadjointPreservesPower) {
  // Ad*_H = [R [p]R; 0 R] (thesis 3.42) is Ad_{H⁻¹}ᵀ: the power WᵀV is frame independent
  Rng rng;
  const SE3 H = rng.pose();
  const Vector6 Vb = rng.v6(), Wb = rng.v6();
  EXPECT_TRUE(coAd(H).isApprox(AdInv(H).transpose(), 1e-13));
  EXPECT_NEAR((coAd(H) * Wb).dot(Ad(H) * Vb), Wb.dot(Vb), 1e-11);
  // a pure force f at the child origin has moment p × Rf about the parent origin (3.43–3.44)
  Vector6 W;
  W << 0, 0, 0, 1, -2, 0.5;
  const Vector6 W0 = coAd(H) * W;
  EXPECT_TRUE(W0.head<3>().isApprox(H.p.cross(H.R * W.tail<3>()), 1e-12));
}

TEST(SE3, InterpolationMovesOriginOnStraightLine) {
  Rng rng;
  const SE3 A = rng.pose(), B = rng.pose();
  EXPECT_TRUE(interpolate(A, B, 0.0).isApprox(A, 1e-12));
  EXPECT_TRUE(interpolate(A, B, 1.0).isApprox(B, 1e-10));
  for (double g : {0.25, 0.5, 0.8}) {
    const SE3 H = interpolate(A, B, g);
    EXPECT_TRUE(H.p.isApprox((1 - g) * A.p + g * B.p, 1e-12));
    // rotation on the geodesic: equal angular steps
    const double total = logSO3(A.R.transpose() * B.R).norm();
    EXPECT_NEAR(logSO3(A.R.transpose() * H.R).norm(), g * total, 1e-10);
    EXPECT_TRUE(isRotation(H.R, 1e-12));
  }
  // the SE(3) geodesic (Alg. 6) reaches the same ends but its origin leaves the line
  const SE3 mid = interpolateSE3(A, B, 0.5);
  EXPECT_TRUE(interpolateSE3(A, B, 1.0).isApprox(B, 1e-9));
  EXPECT_TRUE(mid.R.isApprox(interpolate(A, B, 0.5).R, 1e-10));
  EXPECT_GT((mid.p - 0.5 * (A.p + B.p)).norm(), 1e-3);
}

TEST(SE3, InterpolationFromIdentityEqualsAlgorithm6) {
  // Alg. 6 on SO(3) from the identity: exp((1−γ)·0 + γ log R1)
  Rng rng;
  const SE3 B = rng.pose();
  const SE3 H = interpolate(SE3::Identity(), B, 0.3);
  EXPECT_TRUE(H.R.isApprox(expSO3(0.3 * logSO3(B.R)), 1e-12));
}
