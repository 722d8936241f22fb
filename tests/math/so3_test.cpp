#include "mannequin/math/so3.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

using namespace mannequin::math;

namespace {
using std::numbers::pi;

Vector3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Vector3 v(n(rng), n(rng), n(rng));
  return v.normalized();
}
}  // namespace

TEST(SO3, HatIsCrossProductAndVeeInverts) {
  const Vector3 a(0.3, -1.2, 2.5), b(-0.7, 0.4, 1.1);
  EXPECT_TRUE((hat(a) * b).isApprox(a.cross(b), 1e-15));
  EXPECT_TRUE(vee(hat(a)).isApprox(a, 1e-15));
  EXPECT_TRUE((hat(a) + hat(a).transpose()).isZero(0.0));
}

TEST(SO3, ExpOfQuarterTurnAboutZ) {
  // hand-checked: 90° about z maps x to y
  const Matrix3 R = expSO3(Vector3(0, 0, pi / 2));
  EXPECT_TRUE((R * Vector3::UnitX()).isApprox(Vector3::UnitY(), 1e-15));
  EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
}

TEST(SO3, ExpMatchesTaylorSeriesOfMatrixExponential) {
  const Vector3 w(0.4, -0.2, 0.9);
  // truncated series Σ [ω]^k / k!
  Matrix3 S = Matrix3::Identity(), term = Matrix3::Identity();
  for (int k = 1; k < 30; ++k) {
    term = term * hat(w) / k;
    S += term;
  }
  EXPECT_TRUE(expSO3(w).isApprox(S, 1e-14));
}

TEST(SO3, LogInvertsExpOverRandomAndEdgeAngles) {
  std::mt19937 rng(7);
  const double angles[] = {0.0, 1e-12, 1e-9, 1e-6, 1e-4, 1e-3, 0.5, 2.0, 3.0, pi - 1e-2, pi - 1e-6, pi - 1e-9};
  for (int trial = 0; trial < 50; ++trial) {
    const Vector3 u = randomUnit(rng);
    for (double t : angles) {
      const Vector3 w = t * u;
      const Vector3 back = logSO3(expSO3(w));
      EXPECT_LT((back - w).norm(), 1e-9 + 1e-12) << "angle " << t;
      EXPECT_TRUE(expSO3(back).isApprox(expSO3(w), 1e-12) || (expSO3(back) - expSO3(w)).norm() < 1e-12);
    }
  }
}

TEST(SO3, LogAtExactlyPiGivesAValidVector) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const Vector3 u = randomUnit(rng);
    const Matrix3 R = expSO3(pi * u);
    const Vector3 w = logSO3(R);
    EXPECT_NEAR(w.norm(), pi, 1e-9);
    // ±πu are the same rotation
    EXPECT_LT(std::min((w - pi * u).norm(), (w + pi * u).norm()), 1e-7);
    EXPECT_LT((expSO3(w) - R).norm(), 1e-12);
  }
  // the diagonal case diag(1,-1,-1): rotation by π about x
  Matrix3 Rx = Matrix3::Identity();
  Rx(1, 1) = Rx(2, 2) = -1;
  EXPECT_TRUE(logSO3(Rx).isApprox(Vector3(pi, 0, 0), 1e-12));
}

TEST(SO3, RightJacobianMatchesFiniteDifferences) {
  // exp(ω + δ) ≈ exp(ω) exp(Jr(ω) δ)
  const double angles[] = {1e-8, 1e-3, 0.7, 2.5, 3.1};
  std::mt19937 rng(11);
  for (double t : angles) {
    const Vector3 w = t * randomUnit(rng);
    const Matrix3 Jr = rightJacobianSO3(w);
    const Matrix3 Jl = leftJacobianSO3(w);
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const Vector3 d = Vector3::Unit(k) * h;
      const Vector3 body = logSO3(expSO3(w).transpose() * expSO3(w + d)) / h;
      const Vector3 spatial = logSO3(expSO3(w + d) * expSO3(w).transpose()) / h;
      EXPECT_LT((body - Jr.col(k)).norm(), 1e-5) << "angle " << t;
      EXPECT_LT((spatial - Jl.col(k)).norm(), 1e-5) << "angle " << t;
    }
    EXPECT_TRUE((rightJacobianInverseSO3(w) * Jr).isApprox(Matrix3::Identity(), 1e-10));
    EXPECT_TRUE((leftJacobianInverseSO3(w) * Jl).isApprox(Matrix3::Identity(), 1e-10));
  }
}

TEST(SO3, OrthonormalizeRepairsDriftAndRejectsNaN) {
  Matrix3 R = expSO3(Vector3(0.2, 0.3, -0.1));
  R(0, 1) += 1e-6;
  EXPECT_FALSE(isRotation(R, 1e-9));
  EXPECT_TRUE(isRotation(orthonormalize(R), 1e-12));
  Matrix3 bad = R;
  bad(1, 1) = std::nan("");
  EXPECT_FALSE(isRotation(bad));
  EXPECT_TRUE(orthonormalize(bad).isIdentity(0.0));
}
