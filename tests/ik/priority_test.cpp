// The priority loop (paper eq. 3, 4, 6, 7, 8 and Annex) on random linear problems.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mannequin/ik/priority.hpp"
#include "mannequin/math/pinv.hpp"

namespace mannequin::ik {
namespace {

MatrixX randomMatrix(int r, int c, std::mt19937& g) {
  std::normal_distribution<double> n;
  MatrixX M(r, c);
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < c; ++j) M(i, j) = n(g);
  return M;
}
VectorX randomVector(int r, std::mt19937& g) { return randomMatrix(r, 1, g); }

std::vector<LinearLevel> randomLevels(int p, int m, int n, std::mt19937& g, double damping = 0.0) {
  std::vector<LinearLevel> levels;
  for (int k = 0; k < p; ++k) levels.push_back({randomMatrix(m, n, g), randomVector(m, g), damping});
  return levels;
}

TEST(DampedInverse, MatchesClosedFormAndPlainPseudoInverse) {
  std::mt19937 g(1);
  const MatrixX J = randomMatrix(4, 9, g);
  const double lambda = 0.3;
  const MatrixX closed = J.transpose() * (J * J.transpose() + lambda * lambda * MatrixX::Identity(4, 4)).inverse();
  EXPECT_LT((dampedInverse(J, lambda) - closed).norm(), 1e-12);
  EXPECT_LT((dampedInverse(J, 0.0) - math::pseudoInverse(J, 1e-9)).norm(), 1e-12);
}

TEST(DampedInverse, BoundsTheStepNearASingularity) {
  // J = U diag(1, 1e-6) Vᵀ: the plain inverse amplifies the weak direction by 1e6, the damped
  // one by at most 1/(2λ) (paper Annex, Fig. 4b).
  std::mt19937 g(2);
  const Eigen::HouseholderQR<MatrixX> qu(randomMatrix(2, 2, g)), qv(randomMatrix(7, 7, g));
  const MatrixX U = qu.householderQ(), V = MatrixX(qv.householderQ()).leftCols(2);
  const MatrixX J = U * Eigen::Vector2d(1.0, 1e-6).asDiagonal() * V.transpose();
  const VectorX dx = U.col(1);  // asks motion along the weak direction only
  const double lambda = 0.05;
  PriorityLoop plain(7), damped(7);
  const double n_plain = plain.solve({{J, dx, 0.0}}).norm();
  const double n_damped = damped.solve({{J, dx, lambda}}).norm();
  EXPECT_GT(n_plain, 1e5);
  EXPECT_LE(n_damped, dx.norm() / (2.0 * lambda) + 1e-12);
  EXPECT_LT(n_damped, 1e-3);  // σ/(σ²+λ²) = 1e-6/0.0025 = 4e-4
}

TEST(PriorityLoop, AlgorithmicSingularityTwoLevelsPullingTheSameWayIsBoundedByDamping) {
  // Paper Fig. 4b: two levels whose rows tend to the same direction, J2 = cos ε J1 + sin ε w
  // (w ⊥ J1, unit), each asking a different amount along it. J2 P_N(J1) = sin ε w: without
  // damping level 2's contribution is r2 / sin ε (r2 = Δx2 − J2 Δθ1), unbounded as ε → 0 like
  // 1/distance; with damping λ every level's contribution stays ≤ ‖its Δx‖ / (2λ) (Annex:
  // σ/(σ²+λ²) ≤ 1/(2λ)), and level 1 is met either way.
  std::mt19937 g(11);
  const int n = 7;
  VectorX j1 = randomVector(n, g);
  j1.normalize();
  VectorX w = randomVector(n, g);
  w -= w.dot(j1) * j1;
  w.normalize();
  const double lambda = 0.1, dx1 = 0.3, dx2 = 0.5;
  double previous = 0.0;
  for (double eps : {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6}) {
    const MatrixX J1 = j1.transpose();
    const MatrixX J2 = (std::cos(eps) * j1 + std::sin(eps) * w).transpose();
    const VectorX x1 = VectorX::Constant(1, dx1), x2 = VectorX::Constant(1, dx2);
    PriorityLoop plain(n), damped(n);
    plain.solve({{J1, x1, 0.0}, {J2, x2, 0.0}});
    damped.solve({{J1, x1, lambda}, {J2, x2, lambda}});
    const double r2 = dx2 - std::cos(eps) * dx1;  // Δx2 − J2 Δθ1 with Δθ1 = J1⁺Δx1
    const double c2_plain = plain.contributions().col(1).norm();
    EXPECT_NEAR(c2_plain * std::sin(eps), r2, 1e-9 * r2) << "eps " << eps;  // = r2 / sin ε
    if (previous > 0.0) {
      EXPECT_GT(c2_plain, 9.0 * previous) << "eps " << eps;  // grows like 1/ε (×10 per decade)
    }
    previous = c2_plain;
    // level 1 met up to the rounding of the huge plain step (its error grows with it)
    EXPECT_LT((J1 * plain.dtheta() - x1).norm(), 1e-9 * (1.0 + plain.dtheta().norm())) << "eps " << eps;
    EXPECT_LT((J1 * damped.dtheta() - x1).norm(), 1e-12 + lambda * lambda * dx1) << "eps " << eps;
    // damped: each level's contribution within the Annex bound, for every ε
    const VectorX& c1 = damped.contributions().col(0);
    const VectorX& c2 = damped.contributions().col(1);
    EXPECT_LE(c1.norm(), dx1 / (2.0 * lambda) + 1e-12) << "eps " << eps;
    EXPECT_LE(c2.norm(), dx2 / (2.0 * lambda) + 1e-12) << "eps " << eps;
    EXPECT_LE(c2.norm(), std::abs(dx2 - J2.row(0).dot(c1)) / (2.0 * lambda) + 1e-12) << "eps " << eps;
    EXPECT_LT(damped.dtheta().norm(), (dx1 + dx2) / (2.0 * lambda)) << "eps " << eps;
    // level 2 moves nothing of level 1 (strictness), damped or not
    EXPECT_LT(std::abs(J1.row(0).dot(c2)), 1e-12) << "eps " << eps;
    EXPECT_LT(std::abs(J1.row(0).dot(plain.contributions().col(1))), 1e-9 * c2_plain) << "eps " << eps;
  }
  EXPECT_GT(previous, 1e5);  // at ε = 1e-6 the plain contribution is ~2.1e5
}

TEST(PriorityLoop, TwoLevelsEqualHanafusaFormula) {
  // paper eq. (3): Δθ = J1⁺Δx1 + [J2(I − J1⁺J1)]⁺ (Δx2 − J2 J1⁺ Δx1)
  std::mt19937 g(3);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 12;
    const auto levels = randomLevels(2, 4, n, g);
    const MatrixX& J1 = levels[0].J;
    const MatrixX& J2 = levels[1].J;
    const MatrixX J1p = math::pseudoInverse(J1, 1e-9);
    const MatrixX P1 = MatrixX::Identity(n, n) - J1p * J1;
    const VectorX expected =
        J1p * levels[0].dx + math::pseudoInverse(J2 * P1, 1e-9) * (levels[1].dx - J2 * J1p * levels[0].dx);
    PriorityLoop loop(n);
    EXPECT_LT((loop.solve(levels) - expected).norm(), 1e-10) << "trial " << trial;
  }
}

TEST(PriorityLoop, RecursiveProjectorEqualsFullRecomputation) {
  // eq. (8) and eq. (7) give the same projector and Δθ, also with rank-deficient levels.
  std::mt19937 g(4);
  const int n = 50;
  for (int p = 1; p <= 9; ++p) {
    auto levels = randomLevels(p, 5, n, g, 0.01);
    if (p >= 3) levels[p - 1].J.row(0) = levels[0].J.row(2) - 2.0 * levels[1].J.row(4);  // dependent row
    levels[p - 1].damping = 0.0;  // (a damped last level needs no projector: see below)
    PriorityLoop rec(n, {ProjectorUpdate::kRecursive, 1e-9}), full(n, {ProjectorUpdate::kFull, 1e-9});
    const VectorX a = rec.solve(levels);
    const VectorX b = full.solve(levels);
    EXPECT_LT((a - b).norm(), 1e-9 * (1.0 + b.norm())) << "p = " << p;
    EXPECT_LT((rec.projector() - full.projector()).norm(), 1e-9) << "p = " << p;
    EXPECT_EQ(rec.ranks(), full.ranks());
    if (p >= 3) {
      EXPECT_EQ(rec.ranks()[p - 1], 4);
    }
  }
}

TEST(PriorityLoop, DampedLastLevelByCholeskyEqualsTheSvdForm) {
  // the last level, damped, is solved on its Gram matrix; same result as Ĵ^{+λ} by SVD
  std::mt19937 g(9);
  for (int m_last : {3, 40}) {  // fewer and more rows than coordinates
    const int n = 25;
    auto levels = randomLevels(3, 4, n, g);
    levels.push_back({randomMatrix(m_last, n, g), randomVector(m_last, g), 0.2});
    PriorityLoop loop(n);
    const VectorX d = loop.solve(levels);
    PriorityLoop head(n);
    const VectorX d3 = head.solve({levels[0], levels[1], levels[2]});
    const MatrixX& P3 = head.projector();
    const VectorX expected =
        d3 + dampedInverse(levels[3].J * P3, 0.2) * (levels[3].dx - levels[3].J * d3);
    EXPECT_LT((d - expected).norm(), 1e-10) << "m_last " << m_last;
  }
}

TEST(PriorityLoop, ProjectorIsAnOrthogonalProjectorOntoTheCommonNullSpace) {
  std::mt19937 g(5);
  const int n = 30;
  const auto levels = randomLevels(4, 5, n, g);
  PriorityLoop loop(n);
  loop.solve(levels);
  const MatrixX& P = loop.projector();
  EXPECT_LT((P * P - P).norm(), 1e-10);
  EXPECT_LT((P - P.transpose()).norm(), 1e-10);
  for (const auto& L : levels) EXPECT_LT((L.J * P).norm(), 1e-10);
  EXPECT_NEAR(P.trace(), n - 20, 1e-9);
}

TEST(PriorityLoop, LowerLevelsNeverMoveHigherOnes) {
  // Strictness: J_i Δθ_p = J_i Δθ_i for every i, whatever the lower levels and their damping,
  // including conflicting (infeasible) lower levels.
  std::mt19937 g(6);
  const int n = 20;
  for (int trial = 0; trial < 20; ++trial) {
    auto levels = randomLevels(5, 3, n, g);
    std::uniform_real_distribution<double> lam(0.0, 0.5);
    for (auto& L : levels) L.damping = lam(g);
    levels[3].J = levels[1].J;                 // conflicts with level 2 (asks another Δx)
    PriorityLoop loop(n);
    for (std::size_t i = 0; i < levels.size(); ++i) {
      const std::vector<LinearLevel> upto(levels.begin(), levels.begin() + static_cast<long>(i) + 1);
      const VectorX di = loop.solve(upto);
      const VectorX dp = PriorityLoop(n).solve(levels);
      for (std::size_t h = 0; h <= i; ++h)
        EXPECT_LT((levels[h].J * (dp - di)).norm(), 1e-9) << "trial " << trial << " level " << h << " vs " << i;
    }
    // level 1 undamped and feasible: met exactly
    levels[0].damping = 0.0;
    EXPECT_LT((levels[0].J * PriorityLoop(n).solve(levels) - levels[0].dx).norm(), 1e-9);
  }
}

TEST(PriorityLoop, ClampedCoordinatesTakeTheirImposedVariation) {
  std::mt19937 g(7);
  const int n = 10;
  const auto levels = randomLevels(2, 3, n, g);
  VectorX free = VectorX::Ones(n), d0 = VectorX::Zero(n);
  free(2) = free(7) = 0.0;
  d0(2) = 0.25;
  d0(7) = -0.5;
  PriorityLoop loop(n);
  const VectorX d = loop.solve(levels, &free, &d0);
  EXPECT_DOUBLE_EQ(d(2), 0.25);
  EXPECT_DOUBLE_EQ(d(7), -0.5);
  // level 1 is still met with the remaining 8 coordinates
  EXPECT_LT((levels[0].J * d - levels[0].dx).norm(), 1e-10);
}

TEST(PriorityLoop, RejectsInconsistentInput) {
  std::mt19937 g(8);
  PriorityLoop loop(6);
  auto levels = randomLevels(2, 3, 6, g);
  levels[1].J = randomMatrix(3, 5, g);
  try {
    loop.solve(levels);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("priority level 2"), std::string::npos) << e.what();
  }
  levels = randomLevels(2, 3, 6, g);
  levels[0].dx(1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(loop.solve(levels), std::invalid_argument);
  levels = randomLevels(2, 3, 6, g);
  levels[1].damping = -1.0;
  EXPECT_THROW(loop.solve(levels), std::invalid_argument);
  levels[1].damping = 0.0;
  levels[1].dx.resize(2);
  EXPECT_THROW(loop.solve(levels), std::invalid_argument);
  EXPECT_THROW(PriorityLoop(0), std::invalid_argument);
}

}  // namespace
}  // namespace mannequin::ik
