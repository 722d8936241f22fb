#include <gtest/gtest.h>

#include <limits>

#include "mannequin/lcp/lemke.hpp"
#include "mannequin/lcp/testing.hpp"

using namespace mannequin::lcp;

namespace {

LcpProblem make(std::initializer_list<std::initializer_list<double>> m, std::initializer_list<double> q) {
  LcpProblem p;
  const Index n = static_cast<Index>(q.size());
  p.M.resize(n, n);
  Index i = 0;
  for (auto row : m) {
    Index j = 0;
    for (double v : row) p.M(i, j++) = v;
    ++i;
  }
  p.q.resize(n);
  i = 0;
  for (double v : q) p.q[i++] = v;
  return p;
}

void expectSolved(const LcpResult& r) {
  ASSERT_EQ(r.status, LcpStatus::Solved) << r.message;
  EXPECT_LE(r.residuals.relative_complementarity, 1e-9);
  EXPECT_LE(r.residuals.relative_sign, 1e-9);
  EXPECT_TRUE(r.z.allFinite());
  EXPECT_TRUE(r.w.allFinite());
}

}  // namespace

// Murty's textbook 2×2: z = (4/3, 7/3), w = 0
TEST(Lemke, Murty2x2) {
  LemkeWorkspace ws;
  const auto r = solveLemke(make({{2, 1}, {1, 2}}, {-5, -6}), ws);
  expectSolved(r);
  EXPECT_NEAR(r.z[0], 4.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.z[1], 7.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.w.norm(), 0.0, 1e-12);
}

// lower-triangular P-matrix: z = (1, 0), w = (0, 1)
TEST(Lemke, PMatrix2x2) {
  LemkeWorkspace ws;
  const auto r = solveLemke(make({{1, 0}, {2, 1}}, {-1, -1}), ws);
  expectSolved(r);
  EXPECT_NEAR(r.z[0], 1.0, 1e-12);
  EXPECT_NEAR(r.z[1], 0.0, 1e-12);
  EXPECT_NEAR(r.w[1], 1.0, 1e-12);
}

// tridiagonal SPD 3×3 (hand-checked): z = (1/2, 0, 1/2), w = (0, 2, 0)
TEST(Lemke, Tridiagonal3x3) {
  LemkeWorkspace ws;
  const auto r = solveLemke(make({{2, 1, 0}, {1, 2, 1}, {0, 1, 2}}, {-1, 1, -1}), ws);
  expectSolved(r);
  EXPECT_NEAR(r.z[0], 0.5, 1e-12);
  EXPECT_NEAR(r.z[1], 0.0, 1e-12);
  EXPECT_NEAR(r.z[2], 0.5, 1e-12);
  EXPECT_NEAR(r.w[1], 2.0, 1e-12);
}

// q ≥ 0 needs no pivot
TEST(Lemke, TrivialSolution) {
  LemkeWorkspace ws;
  const auto r = solveLemke(make({{1, 2}, {3, 4}}, {0, 1}), ws);
  expectSolved(r);
  EXPECT_EQ(r.pivots, 0);
  EXPECT_EQ(r.z.norm(), 0.0);
}

// PSD, infeasible: w1 + w2 = −2 for every z, so Lemke must end on a ray
TEST(Lemke, InfeasibleRay) {
  LemkeWorkspace ws;
  const auto r = solveLemke(make({{1, -1}, {-1, 1}}, {-1, -1}), ws);
  EXPECT_EQ(r.status, LcpStatus::NoSolution);
  EXPECT_TRUE(r.z.allFinite());
}

// contact rows n and −n at the same point with both distances negative: infeasible
TEST(Lemke, InfeasibleOpposedContacts) {
  auto c = gen::makeContactLike(6, 7);
  c.A.row(1) = -c.A.row(0);
  LcpProblem p{c.A * c.A.transpose(), c.lcp.q};
  p.q[0] = -0.01;
  p.q[1] = -0.01;
  LemkeWorkspace ws;
  const auto r = solveLemke(p, ws);
  EXPECT_EQ(r.status, LcpStatus::NoSolution) << r.message;
}

// degenerate: repeated rows and zeros in q
TEST(Lemke, DegenerateRepeatedRows) {
  LemkeWorkspace ws;
  const auto r = solveLemke(make({{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, {-1, -1, 0}), ws);
  expectSolved(r);
  EXPECT_NEAR(r.z.sum(), 1.0, 1e-12);
  EXPECT_NEAR(r.w[0], 0.0, 1e-12);
  EXPECT_NEAR(r.w[2], 1.0, 1e-12);
}

TEST(Lemke, DegenerateZerosInQ) {
  LemkeWorkspace ws;
  auto p = gen::makePsd(12, 3, 5);
  for (Index i = 0; i < 12; i += 2) p.q[i] = 0.0;
  p.q[1] = -1.0;
  p.M.row(3) = p.M.row(1);
  p.M.col(3) = p.M.col(1);
  p.q[3] = p.q[1];
  const auto r = solveLemke(p, ws);
  ASSERT_TRUE(r.status == LcpStatus::Solved || r.status == LcpStatus::NoSolution) << r.message;
  if (r.status == LcpStatus::Solved) expectSolved(r);
}

// bad input is reported, never a crash
TEST(Lemke, InvalidInput) {
  LemkeWorkspace ws;
  LcpProblem p{Eigen::MatrixXd::Identity(2, 3), Eigen::VectorXd::Ones(2)};
  EXPECT_EQ(solveLemke(p, ws).status, LcpStatus::Invalid);
  p = LcpProblem{Eigen::MatrixXd::Identity(2, 2), Eigen::VectorXd::Ones(3)};
  EXPECT_EQ(solveLemke(p, ws).status, LcpStatus::Invalid);
  p = LcpProblem{Eigen::MatrixXd::Identity(2, 2), Eigen::VectorXd::Ones(2)};
  p.M(0, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(solveLemke(p, ws).status, LcpStatus::Invalid);
  p.M(0, 1) = 0.0;
  p.q[1] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(solveLemke(p, ws).status, LcpStatus::Invalid);
  LemkeOptions o;
  o.covering = Eigen::VectorXd::Constant(2, -1.0);
  p.q[1] = -1.0;
  EXPECT_EQ(solveLemke(p, ws, o).status, LcpStatus::Invalid);
}

// a covering vector changes the path, not the (unique) answer of a P-matrix LCP
TEST(Lemke, CoveringVector) {
  const auto p = gen::makeSpd(20, 3);
  LemkeWorkspace ws;
  const auto r1 = solveLemke(p, ws);
  LemkeOptions o;
  o.covering = Eigen::VectorXd::LinSpaced(20, 0.5, 2.0);
  const auto r2 = solveLemke(p, ws, o);
  expectSolved(r1);
  expectSolved(r2);
  EXPECT_LE((r1.z - r2.z).lpNorm<Eigen::Infinity>(), 1e-10);
}

TEST(Lemke, PivotLimit) {
  const auto p = gen::makeSpd(30, 4);
  LemkeWorkspace ws;
  LemkeOptions o;
  o.max_pivots = 2;
  o.retries = 0;
  const auto r = solveLemke(p, ws, o);
  EXPECT_EQ(r.status, LcpStatus::PivotLimit);
  EXPECT_TRUE(r.z.allFinite());
}

// property: every solved answer is complementary to 1e-9 relative, over families
TEST(Lemke, RandomFamiliesSolvedAreComplementary) {
  LemkeWorkspace ws;
  int solved = 0;
  for (std::uint32_t seed = 1; seed <= 15; ++seed) {
    const Index n = 5 + static_cast<Index>(seed % 4) * 10;
    for (const auto& p : {gen::makeSpd(n, seed), gen::makePMatrix(n, seed),
                          gen::makeCopositive(n, seed)}) {
      const auto r = solveLemke(p, ws);
      expectSolved(r);  // SPD, P and strictly copositive LCPs always have a solution
      ++solved;
    }
    const auto psd = gen::makePsd(n, n / 3 + 1, seed);
    const auto r = solveLemke(psd, ws);
    ASSERT_NE(r.status, LcpStatus::PivotLimit);
    if (r.status == LcpStatus::Solved) expectSolved(r);
  }
  EXPECT_EQ(solved, 45);
}

// contact-like M = J b⁻¹ Jᵀ (rank ≤ 42), exact PSD and regularised; always feasible
TEST(Lemke, ContactLike) {
  LemkeWorkspace ws;
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    for (Index n : {10, 60, 120}) {
      const auto c = gen::makeContactLike(n, seed);
      const auto r = solveLemke(c.lcp, ws);
      expectSolved(r);
      const auto creg = gen::makeContactLike(n, seed, 1e-8);
      expectSolved(solveLemke(creg.lcp, ws));
    }
  }
}

// larger contact-like problems (n = 300 > 42 DoF, rank-deficient): solved exactly
TEST(Lemke, ContactLikeLarge) {
  LemkeWorkspace ws;
  for (std::uint32_t seed = 1; seed <= 8; ++seed) {
    const auto c = gen::makeContactLike(300, seed);
    expectSolved(solveLemke(c.lcp, ws));
  }
}
