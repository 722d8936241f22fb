#include "mannequin/math/pinv.hpp"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <random>
#include <stdexcept>

using namespace mannequin::math;

namespace {
MatrixX randomMatrix(int rows, int cols, unsigned seed) {
  std::mt19937 g(seed);
  std::normal_distribution<double> n;
  MatrixX M(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) M(i, j) = n(g);
  return M;
}
// a rows×cols matrix of exact rank r
MatrixX rankDeficient(int rows, int cols, int r, unsigned seed) {
  return randomMatrix(rows, r, seed) * randomMatrix(r, cols, seed + 1);
}
}  // namespace

TEST(PseudoInverse, PenroseConditionsAndRank) {
  for (int r : {2, 4, 6}) {
    const MatrixX J = rankDeficient(6, 10, r, 5 + r);
    int rank = -1;
    const MatrixX P = pseudoInverse(J, 1e-9, &rank);
    EXPECT_EQ(rank, r);
    EXPECT_TRUE((J * P * J).isApprox(J, 1e-10));
    EXPECT_TRUE((P * J * P).isApprox(P, 1e-10));
    EXPECT_TRUE((J * P).transpose().isApprox(J * P, 1e-10));
    EXPECT_TRUE((P * J).transpose().isApprox(P * J, 1e-10));
  }
}

TEST(PseudoInverse, HandCheckedDiagonal) {
  MatrixX J(2, 3);
  J << 2, 0, 0,
       0, 1e-12, 0;
  int rank = 0;
  const MatrixX P = pseudoInverse(J, 1e-9, &rank);
  EXPECT_EQ(rank, 1);  // 1e-12 is below the threshold: treated as zero, not inverted to 1e12
  MatrixX expected = MatrixX::Zero(3, 2);
  expected(0, 0) = 0.5;
  EXPECT_TRUE(P.isApprox(expected, 1e-15));
}

TEST(PseudoInverse, CODAgreesWithSVD) {
  for (int r : {3, 6}) {
    const MatrixX J = rankDeficient(6, 12, r, 17 + r);
    int r_svd = 0, r_cod = 0;
    const MatrixX A = pseudoInverse(J, 1e-9, &r_svd);
    const MatrixX B = pseudoInverseCOD(J, 1e-9, &r_cod);
    EXPECT_EQ(r_svd, r_cod);
    EXPECT_LT((A - B).norm(), 1e-9 * A.norm());
  }
}

TEST(DampedPseudoInverse, LLTEqualsSVDAndIsBounded) {
  for (auto [rows, cols] : {std::pair{6, 10}, std::pair{10, 6}}) {
    const MatrixX J = randomMatrix(rows, cols, 23);
    const double lambda = 0.3;
    const MatrixX A = dampedPseudoInverse(J, lambda);
    const MatrixX B = dampedPseudoInverseSVD(J, lambda);
    EXPECT_TRUE(A.isApprox(B, 1e-11));
  }
  // near a singularity the damped inverse stays bounded by 1/(2λ) while the plain one explodes
  MatrixX J(2, 2);
  J << 1, 0,
       0, 1e-8;
  const double lambda = 0.1;
  const double norm_damped = Eigen::JacobiSVD<MatrixX>(dampedPseudoInverse(J, lambda)).singularValues()(0);
  EXPECT_LE(norm_damped, 1.0 / (2 * lambda) + 1e-12);
  EXPECT_GT(pseudoInverse(J, 0.0).norm(), 1e7);
}

TEST(Projector, IdempotentSymmetricAndAnnihilatesJ) {
  const MatrixX J = randomMatrix(6, 15, 31);
  const MatrixX P = nullSpaceProjector(J, 1e-9);
  EXPECT_LT((J * P).norm(), 1e-12);
  EXPECT_LT((P * P - P).norm(), 1e-12);
  EXPECT_LT((P - P.transpose()).norm(), 1e-12);
  // trace = n − rank
  EXPECT_NEAR(P.trace(), 15 - 6, 1e-10);
}

TEST(Projector, WeightedIsDynamicallyConsistent) {
  const int n = 12;
  const MatrixX J = rankDeficient(5, n, 4, 41);  // rank-deficient task as well
  const MatrixX L = randomMatrix(n, n, 43);
  const MatrixX W = L * L.transpose() + MatrixX::Identity(n, n);  // SPD, like b_a
  const MatrixX P = weightedNullSpaceProjector(J, W, 1e-9);
  const MatrixX Winv = W.inverse();
  EXPECT_LT((J * P).norm(), 1e-10);                    // JΠ = 0
  EXPECT_LT((P * P - P).norm(), 1e-10);                // idempotent
  EXPECT_LT((J * Winv * P.transpose()).norm(), 1e-10); // 2.74–2.76: J b⁻¹ Πᵀ = 0
  // with W = I it is the plain projector
  EXPECT_LT((weightedNullSpaceProjector(J, MatrixX::Identity(n, n), 1e-9) - nullSpaceProjector(J, 1e-9)).norm(), 1e-10);
}

TEST(Projector, WeightedRejectsBadWeights) {
  const MatrixX J = randomMatrix(3, 5, 1);
  EXPECT_THROW(weightedNullSpaceProjector(J, MatrixX::Identity(4, 4), 1e-9), std::invalid_argument);
  MatrixX notSpd = MatrixX::Identity(5, 5);
  notSpd(2, 2) = -1;
  EXPECT_THROW(weightedNullSpaceProjector(J, notSpd, 1e-9), std::invalid_argument);
}
