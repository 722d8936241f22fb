#include <gtest/gtest.h>

#include <limits>

#include "mannequin/lcp/lemke.hpp"
#include "mannequin/lcp/pgs.hpp"
#include "mannequin/lcp/structured.hpp"
#include "mannequin/lcp/testing.hpp"

using namespace mannequin::lcp;

// PGS on a well-conditioned SPD LCP matches Lemke's unique solution
TEST(Pgs, MatchesLemkeOnSpd) {
  LemkeWorkspace lw;
  PgsWorkspace pw;
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    const auto p = gen::makeSpd(40, seed);
    const auto rl = solveLemke(p, lw);
    ASSERT_EQ(rl.status, LcpStatus::Solved);
    for (double omega : {1.0, 1.3}) {
      PgsOptions o;
      o.relaxation = omega;
      const auto rp = solvePgs(p, pw, o);
      ASSERT_EQ(rp.status, LcpStatus::Solved) << rp.message;
      EXPECT_LE(rp.residuals.relative_complementarity, 1e-9);
      EXPECT_LE((rp.z - rl.z).lpNorm<Eigen::Infinity>(), 1e-8);
    }
  }
}

TEST(Pgs, WarmStartNeedsFewerSweeps) {
  const auto p = gen::makeSpd(30, 9);
  PgsWorkspace pw;
  const auto cold = solvePgs(p, pw);
  ASSERT_EQ(cold.status, LcpStatus::Solved);
  PgsOptions o;
  o.warm_start = true;
  const auto warm = solvePgs(p, pw, o);
  ASSERT_EQ(warm.status, LcpStatus::Solved);
  EXPECT_LT(warm.pivots, cold.pivots);
}

TEST(Pgs, InvalidAndLimits) {
  PgsWorkspace pw;
  LcpProblem p{Eigen::MatrixXd::Zero(2, 2), -Eigen::VectorXd::Ones(2)};
  EXPECT_EQ(solvePgs(p, pw).status, LcpStatus::Invalid);  // zero diagonal
  p.M.setIdentity();
  PgsOptions o;
  o.relaxation = 2.5;
  EXPECT_EQ(solvePgs(p, pw, o).status, LcpStatus::Invalid);
  p.q[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(solvePgs(p, pw).status, LcpStatus::Invalid);
  // degenerate contact LCP: a 3-sweep budget is not enough and says so
  const auto c = gen::makeContactLike(80, 3);
  o = PgsOptions{};
  o.max_iterations = 3;
  const auto r = solvePgs(c.lcp, pw, o);
  EXPECT_EQ(r.status, LcpStatus::PivotLimit);
  EXPECT_TRUE(r.z.allFinite());
  EXPECT_GE(r.z.minCoeff(), 0.0);
}

// the structured path returns Lemke's w and Aᵀz (unique) on contact-like problems
TEST(Structured, MatchesLemkeOnContactLike) {
  LemkeWorkspace lw;
  StructuredWorkspace sw;
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    for (Index n : {8, 50, 150}) {
      const auto c = gen::makeContactLike(n, seed);
      const auto rl = solveLemke(c.lcp, lw);
      const auto rs = solveStructured(StructuredProblem{c.A, c.lcp.q}, sw);
      ASSERT_EQ(rl.status, LcpStatus::Solved) << rl.message;
      ASSERT_EQ(rs.status, LcpStatus::Solved) << rs.message;
      EXPECT_LE(rs.residuals.relative_complementarity, 1e-9);
      EXPECT_LE(rs.residuals.relative_sign, 1e-9);
      const Eigen::VectorXd xl = c.A.transpose() * rl.z;
      EXPECT_LE((rs.w - rl.w).lpNorm<Eigen::Infinity>(), 1e-9 * (1 + rl.w.lpNorm<Eigen::Infinity>()));
      EXPECT_LE((sw.x_ - xl).lpNorm<Eigen::Infinity>(), 1e-9 * (1 + xl.lpNorm<Eigen::Infinity>()));
    }
  }
}

// warm start from the previous active set: same answer, fewer steps on a perturbed problem
TEST(Structured, WarmStart) {
  auto c = gen::makeContactLike(200, 11);
  StructuredWorkspace sw;
  StructuredOptions cold_opt;
  cold_opt.warm_start = false;
  const auto first = solveStructured(StructuredProblem{c.A, c.lcp.q}, sw, cold_opt);
  ASSERT_EQ(first.status, LcpStatus::Solved);
  c.lcp.q *= 1.01;
  const auto cold = solveStructured(StructuredProblem{c.A, c.lcp.q}, sw, cold_opt);
  solveStructured(StructuredProblem{c.A, c.lcp.q * (1.0 / 1.01)}, sw, cold_opt);
  const auto warm = solveStructured(StructuredProblem{c.A, c.lcp.q}, sw);
  ASSERT_EQ(cold.status, LcpStatus::Solved);
  ASSERT_EQ(warm.status, LcpStatus::Solved);
  EXPECT_LE((cold.w - warm.w).lpNorm<Eigen::Infinity>(), 1e-10);
  EXPECT_LT(warm.pivots, cold.pivots);
}

TEST(Structured, InfeasibleAndInvalid) {
  StructuredWorkspace sw;
  Eigen::MatrixXd A(2, 1);
  A << 1.0, -1.0;
  EXPECT_EQ(solveStructured(StructuredProblem{A, Eigen::Vector2d(-1.0, -1.0)}, sw).status, LcpStatus::NoSolution);
  EXPECT_EQ(solveStructured(StructuredProblem{A, Eigen::Vector3d(-1.0, -1.0, 0.0)}, sw).status, LcpStatus::Invalid);
  A(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(solveStructured(StructuredProblem{A, Eigen::Vector2d(-1.0, -1.0)}, sw).status, LcpStatus::Invalid);
}

// factorPsd recovers M = A Aᵀ at the true rank and rejects indefinite or non-symmetric M
TEST(Structured, FactorPsd) {
  const auto p = gen::makePsd(30, 7, 2);
  Eigen::MatrixXd A;
  ASSERT_EQ(factorPsd(p.M, A), nullptr);
  EXPECT_EQ(A.cols(), 7);
  EXPECT_LE((A * A.transpose() - p.M).lpNorm<Eigen::Infinity>(), 1e-10);
  Eigen::Matrix2d bad;
  bad << 1, 0, 0, -1;
  EXPECT_NE(factorPsd(bad, A), nullptr);
  bad << 1, 2, 0, 1;
  EXPECT_NE(factorPsd(bad, A), nullptr);
  // structured solve of a general PSD LCP through the factor agrees with Lemke on w
  LemkeWorkspace lw;
  StructuredWorkspace sw;
  const auto spd = gen::makeSpd(25, 4);
  ASSERT_EQ(factorPsd(spd.M, A), nullptr);
  const auto rs = solveStructured(StructuredProblem{A, spd.q}, sw);
  const auto rl = solveLemke(spd, lw);
  ASSERT_EQ(rs.status, LcpStatus::Solved);
  EXPECT_LE((rs.z - rl.z).lpNorm<Eigen::Infinity>(), 1e-9);
}
