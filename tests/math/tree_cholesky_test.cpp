// TreeCholesky: b = Lᵀ L along a tree of coordinates (Featherstone's LTL), checked against a known
// factor, against Eigen's dense solve, and on the controller-like pattern b = diag + Σ Jᵀ B J.
#include "mannequin/math/tree_cholesky.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

namespace {

using mannequin::math::MatrixX;
using mannequin::math::TreeCholesky;
using mannequin::math::VectorX;

// a random forest: parent[i] uniform in [−1, i)
std::vector<int> randomTree(int n, std::mt19937& rng) {
  std::vector<int> p(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) p[static_cast<std::size_t>(i)] = std::uniform_int_distribution<int>(-1, i - 1)(rng);
  return p;
}

bool related(const std::vector<int>& p, int i, int j) {  // one is an ancestor of the other (or equal)
  if (i < j) std::swap(i, j);
  for (int k = i; k != -1; k = p[static_cast<std::size_t>(k)])
    if (k == j) return true;
  return false;
}

// a random lower-triangular L with the tree's pattern and a positive diagonal
MatrixX randomFactor(const std::vector<int>& p, std::mt19937& rng) {
  const int n = static_cast<int>(p.size());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatrixX L = MatrixX::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    L(k, k) = 0.5 + std::abs(u(rng));
    for (int i = p[static_cast<std::size_t>(k)]; i != -1; i = p[static_cast<std::size_t>(i)]) L(k, i) = u(rng);
  }
  return L;
}

TEST(TreeCholesky, RecoversTheFactorOfLtLOnRandomTrees) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 1 + trial % 45;
    const auto p = randomTree(n, rng);
    const MatrixX L = randomFactor(p, rng);
    const MatrixX b = L.transpose() * L;
    // LᵀL has the tree's pattern: nothing off it
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        if (!related(p, i, j)) { ASSERT_EQ(b(i, j), 0.0) << i << "," << j; }
      }
    TreeCholesky f(p);
    ASSERT_EQ(f.compute(b), Eigen::Success);
    // the factor with a positive diagonal is unique
    EXPECT_LT((f.matrixL() - L).norm(), 1e-10 * L.norm()) << "n = " << n;
    EXPECT_LT((f.matrixL().transpose() * f.matrixL() - b).norm(), 1e-12 * b.norm());
  }
}

TEST(TreeCholesky, SolvesLikeADenseFactorisation) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 2 + trial;
    const auto p = randomTree(n, rng);
    const MatrixX L = randomFactor(p, rng);
    const MatrixX b = L.transpose() * L;
    TreeCholesky f(p);
    ASSERT_EQ(f.compute(b), Eigen::Success);
    const VectorX y = VectorX::Random(n);
    VectorX x = y;
    f.solveInPlace(x);
    const VectorX ref = b.ldlt().solve(y);
    EXPECT_LT((x - ref).norm(), 1e-9 * (1 + ref.norm()));
    EXPECT_LT((b * x - y).norm(), 1e-10 * (1 + y.norm()));
    // several columns at once
    const MatrixX Y = MatrixX::Random(n, 3);
    MatrixX X = Y;
    f.solveInPlace(X);
    EXPECT_LT((b * X - Y).norm(), 1e-10 * (1 + Y.norm()));
  }
}

TEST(TreeCholesky, HalfSolveGivesTheDelassusMatrixAndKeepsABranchSupport) {
  std::mt19937 rng(3);
  const int n = 40;
  const auto p = randomTree(n, rng);
  const MatrixX b = [&] {
    const MatrixX L = randomFactor(p, rng);
    return MatrixX(L.transpose() * L);
  }();
  TreeCholesky f(p);
  ASSERT_EQ(f.compute(b), Eigen::Success);
  // rows supported by a branch (the coordinates moving a body: k and its ancestors)
  MatrixX R = MatrixX::Zero(6, n);
  for (int r = 0; r < 6; ++r) {
    const int k = std::uniform_int_distribution<int>(0, n - 1)(rng);
    for (int i = k; i != -1; i = p[static_cast<std::size_t>(i)]) R(r, i) = std::uniform_real_distribution<double>(-1, 1)(rng);
  }
  MatrixX X = R.transpose();
  for (int c = 0; c < 6; ++c) f.halfSolveInPlace(X.col(c));
  const MatrixX A = R * b.ldlt().solve(R.transpose());
  EXPECT_LT((X.transpose() * X - A).norm(), 1e-9 * (1 + A.norm()));
  for (int c = 0; c < 6; ++c)
    for (int i = 0; i < n; ++i) {
      if (R(c, i) == 0.0) { EXPECT_EQ(X(i, c), 0.0) << "row " << c << " gained coordinate " << i; }
    }
}

TEST(TreeCholesky, DenseChainAndDiagonalAreTheTwoExtremes) {
  const int n = 12;
  const MatrixX A = MatrixX::Random(n, n);
  const MatrixX b = A * A.transpose() + n * MatrixX::Identity(n, n);  // dense SPD
  TreeCholesky chain = TreeCholesky::dense(n);
  ASSERT_EQ(chain.compute(b), Eigen::Success);
  EXPECT_LT((chain.matrixL().transpose() * chain.matrixL() - b).norm(), 1e-12 * b.norm());
  const VectorX y = VectorX::Random(n);
  VectorX x = y;
  chain.solveInPlace(x);
  EXPECT_LT((b * x - y).norm(), 1e-10 * y.norm());
  // no parents: a diagonal b (off-diagonal entries are off the pattern and not read)
  TreeCholesky diag(std::vector<int>(n, -1));
  ASSERT_EQ(diag.compute(b), Eigen::Success);
  x = y;
  diag.solveInPlace(x);
  EXPECT_LT((x - y.cwiseQuotient(b.diagonal())).norm(), 1e-14 * x.norm());
}

TEST(TreeCholesky, ThePackedPatternGivesTheSameFactorBitForBit) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 1 + trial % 45;
    const auto p = randomTree(n, rng);
    const MatrixX L = randomFactor(p, rng);
    const MatrixX b = L.transpose() * L;
    TreeCholesky dense(p), packed(p);
    ASSERT_EQ(dense.compute(b), Eigen::Success);
    // pack by packedIndex: every ancestor pair has a slot, each slot once, nothing else has one
    VectorX diagonal = b.diagonal(), lower = VectorX::Constant(packed.packedSize(), std::nan(""));
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < n; ++i) {
        const int slot = packed.packedIndex(k, i);
        const bool ancestor = i < k && related(p, k, i);
        ASSERT_EQ(slot >= 0, ancestor) << "n = " << n << ", b(" << k << ", " << i << ")";
        if (!ancestor) continue;
        ASSERT_LT(slot, packed.packedSize());
        ASSERT_TRUE(std::isnan(lower(slot))) << "slot " << slot << " given twice";
        lower(slot) = b(k, i);
      }
    ASSERT_FALSE(lower.hasNaN()) << "a slot no ancestor pair fills";
    ASSERT_EQ(packed.computePacked(diagonal, lower), Eigen::Success);
    EXPECT_EQ(packed.matrixL(), dense.matrixL()) << "n = " << n;
  }
  TreeCholesky f = TreeCholesky::dense(3);
  EXPECT_EQ(f.packedIndex(-1, 0), -1);
  EXPECT_EQ(f.packedIndex(3, 0), -1);
  EXPECT_THROW(f.computePacked(VectorX::Ones(2), VectorX::Zero(3)), std::invalid_argument);
  EXPECT_THROW(f.computePacked(VectorX::Ones(3), VectorX::Zero(2)), std::invalid_argument);
  VectorX d = VectorX::Ones(3);
  d(1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(f.computePacked(d, VectorX::Zero(3)), Eigen::NumericalIssue);
}

TEST(TreeCholesky, RejectsBadTreesSizesAndIndefiniteMatrices) {
  EXPECT_THROW(TreeCholesky({-1, 1}), std::invalid_argument);   // parent not before the child
  EXPECT_THROW(TreeCholesky({-2}), std::invalid_argument);
  TreeCholesky f = TreeCholesky::dense(3);
  EXPECT_EQ(f.info(), Eigen::InvalidInput);  // nothing factorised yet
  EXPECT_THROW(f.compute(MatrixX::Identity(2, 2)), std::invalid_argument);
  MatrixX b = MatrixX::Identity(3, 3);
  b(2, 0) = 2.0;  // eigenvalue 1 − 2 < 0
  EXPECT_EQ(f.compute(b), Eigen::NumericalIssue);
  b = MatrixX::Identity(3, 3);
  b(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(f.compute(b), Eigen::NumericalIssue);
  EXPECT_EQ(f.compute(MatrixX::Identity(3, 3)), Eigen::Success);
}

}  // namespace
