#include <gtest/gtest.h>

#include <Eigen/QR>
#include <limits>
#include <random>
#include <string>
#include <vector>

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

// Independent decision of solvability for small n, by enumeration. Write w − M z = q as A x = q
// with A = [I, −M] and x = (w, z) ≥ 0. If the LCP has a solution, the solutions with the same
// support form a polyhedron in the orthant, which has a vertex: a nonnegative x on linearly
// independent columns, taken from a complementary set (for each i: w_i, or z_i, or neither).
// Trying every such set (3ⁿ) for a nonnegative least-squares-consistent x decides solvability.
// Returns true and fills z when one is found (residuals at `tol` relative to the data).
bool solvableByEnumeration(const LcpProblem& p, Eigen::VectorXd* z_found = nullptr, double tol = 1e-9) {
  const Index n = p.q.size();
  if (n > 12) {
    ADD_FAILURE() << "enumeration is for n <= 12, got " << n;
    return false;
  }
  const double scale = 1.0 + std::max(p.M.cwiseAbs().maxCoeff(), p.q.cwiseAbs().maxCoeff());
  long total = 1;
  for (Index i = 0; i < n; ++i) total *= 3;
  Eigen::MatrixXd A(n, n);
  std::vector<Index> which(static_cast<std::size_t>(n));  // 0 neither, 1 w_i, 2 z_i
  for (long code = 0; code < total; ++code) {
    long c = code;
    Index k = 0;
    for (Index i = 0; i < n; ++i, c /= 3) {
      which[static_cast<std::size_t>(i)] = static_cast<Index>(c % 3);
      if (c % 3 == 1) A.col(k++) = Eigen::VectorXd::Unit(n, i);
      if (c % 3 == 2) A.col(k++) = -p.M.col(i);
    }
    Eigen::VectorXd x = Eigen::VectorXd::Zero(k);
    if (k > 0) x = A.leftCols(k).colPivHouseholderQr().solve(p.q);
    if (k > 0 && x.minCoeff() < -tol * scale) continue;
    if ((A.leftCols(k) * x - p.q).lpNorm<Eigen::Infinity>() > tol * scale) continue;
    if (z_found != nullptr) {
      z_found->setZero(n);
      Index col = 0;
      for (Index i = 0; i < n; ++i) {
        const Index w = which[static_cast<std::size_t>(i)];
        if (w == 2) (*z_found)[i] = std::max(0.0, x[col]);
        if (w != 0) ++col;
      }
    }
    return true;
  }
  return false;
}

// Lemke on a PSD (hence copositive-plus) M is a decision procedure: Solved iff a solution exists,
// NoSolution (ray) iff none. Checks the answer against the independent decision.
void expectLemkeDecides(const LcpProblem& p, bool solvable, LemkeWorkspace& ws, const std::string& what) {
  SCOPED_TRACE(what);
  const auto r = solveLemke(p, ws);
  if (solvable) {
    expectSolved(r);
  } else {
    EXPECT_EQ(r.status, LcpStatus::NoSolution) << r.message;
  }
}

// Symmetric PSD M = BBᵀ (B n×r) with a known solution: z* ≥ 0 on a random support, w* ≥ 0 on the
// rest, some of both exactly 0 (degenerate), q = w* − M z*.
LcpProblem psdWithSolution(Index n, Index r, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  LcpProblem p;
  const Eigen::MatrixXd B = gen::uniform(n, r, -1.0, 1.0, rng);
  p.M = B * B.transpose();
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n), w = Eigen::VectorXd::Zero(n);
  for (Index i = 0; i < n; ++i) {
    const double pick = u(rng);
    if (pick < 0.4) z[i] = u(rng);
    else if (pick < 0.8) w[i] = u(rng);  // else both 0
  }
  p.q = w - p.M * z;
  return p;
}

// Symmetric PSD M = BBᵀ with an infeasibility certificate y ≥ 0, M y = 0, qᵀy < 0: B's columns are
// made orthogonal to y, and q is shifted along y. Then for any z ≥ 0, yᵀ(M z + q) = qᵀy < 0, so
// M z + q ≥ 0 is impossible: the LCP has no solution.
LcpProblem psdInfeasible(Index n, Index r, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  for (Index i = 0; i < n; ++i)
    if (u(rng) < 0.3) y[i] = u(rng);
  y[static_cast<Index>(u(rng) * static_cast<double>(n)) % n] = 1.0;  // y ≠ 0
  Eigen::MatrixXd B = gen::uniform(n, r, -1.0, 1.0, rng);
  B -= y * (y.transpose() * B) / y.squaredNorm();
  LcpProblem p;
  p.M = B * B.transpose();
  p.q = gen::uniform(n, 1, -1.0, 1.0, rng);
  p.q -= (p.q.dot(y) + 0.1 * y.norm()) / y.squaredNorm() * y;  // qᵀy = −0.1‖y‖
  EXPECT_LE((p.M * y).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT(p.q.dot(y), 0.0);
  return p;
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
  // M stays PSD (row and column 3 copy 1: M = B'B'ᵀ); solvable or not, Lemke must decide it
  expectLemkeDecides(p, solvableByEnumeration(p), ws, "zeros in q, repeated row");
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
  }
  EXPECT_EQ(solved, 45);
}

// PSD (copositive-plus): Lemke solves whenever a solution exists and reports NoSolution only when
// there is none, decided independently by enumeration (n ≤ 8), including degenerate variants
// (zeros in q, repeated rows). Both outcomes must occur in the family for the test to mean anything.
TEST(Lemke, PsdAgreesWithEnumeration) {
  LemkeWorkspace ws;
  int solvable = 0, unsolvable = 0;
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    const Index n = 2 + static_cast<Index>(seed % 7);
    const Index r = 1 + static_cast<Index>(seed % static_cast<std::uint32_t>(n));
    std::vector<LcpProblem> family{gen::makePsd(n, r, seed)};
    LcpProblem zeros = family[0];
    for (Index i = 0; i < n; i += 2) zeros.q[i] = 0.0;
    family.push_back(zeros);
    if (n >= 3) {
      LcpProblem repeated = family[0];
      repeated.M.row(2) = repeated.M.row(0);
      repeated.M.col(2) = repeated.M.col(0);
      repeated.q[2] = repeated.q[0];
      family.push_back(repeated);
    }
    for (std::size_t f = 0; f < family.size(); ++f) {
      const bool has = solvableByEnumeration(family[f]);
      (has ? solvable : unsolvable)++;
      expectLemkeDecides(family[f], has, ws, "seed " + std::to_string(seed) + " n " + std::to_string(n) +
                                                 " rank " + std::to_string(r) + " variant " + std::to_string(f));
    }
  }
  EXPECT_GT(solvable, 0);
  EXPECT_GT(unsolvable, 0);
}

// the enumeration agrees with the theory on the classes where a solution always exists
TEST(Lemke, EnumerationFindsTheSolutionOfPAndCopositiveProblems) {
  LemkeWorkspace ws;
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    const Index n = 2 + static_cast<Index>(seed % 6);
    for (const auto& p : {gen::makeSpd(n, seed), gen::makePMatrix(n, seed), gen::makeCopositive(n, seed)}) {
      ASSERT_TRUE(solvableByEnumeration(p));
      expectSolved(solveLemke(p, ws));
    }
    // P-matrix: the solution is unique, so Lemke's is the enumerated one
    for (const auto& p : {gen::makeSpd(n, seed), gen::makePMatrix(n, seed)}) {
      Eigen::VectorXd z;
      ASSERT_TRUE(solvableByEnumeration(p, &z));
      EXPECT_LE((solveLemke(p, ws).z - z).lpNorm<Eigen::Infinity>(), 1e-8);
    }
  }
}

// larger PSD problems (n up to 60, rank-deficient) built with a known solution or a known
// infeasibility certificate: Solved for the first, NoSolution for the second, every time
TEST(Lemke, PsdWithKnownSolutionOrCertificate) {
  LemkeWorkspace ws;
  for (std::uint32_t seed = 1; seed <= 12; ++seed) {
    for (Index n : {15, 25, 35, 60}) {
      for (Index r : {Index{1}, n / 3 + 1, n}) {
        const std::string what = "seed " + std::to_string(seed) + " n " + std::to_string(n) + " rank " + std::to_string(r);
        expectLemkeDecides(psdWithSolution(n, r, seed), true, ws, "known solution, " + what);
        expectLemkeDecides(psdInfeasible(n, r, seed), false, ws, "certificate, " + what);
      }
    }
  }
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

// the product form (eta file, the default) and the dense tableau follow the same pivoting rules: on
// the same problems both solve, with the same pivot count and the same z up to rounding; includes
// degenerate problems (zeros in q, repeated rows) where the lexicographic tie-break decides the path.
// A contact-like M with more rows than its 42 columns is singular: its solutions z form a set (w = Mz + q
// is the same for all of them, M being symmetric PSD), and rounding differences between the two forms
// may break a near-tie differently on the way; there both must solve and give the same w.
TEST(Lemke, ProductFormAgreesWithDenseTableau) {
  LemkeWorkspace ws_product, ws_dense;
  LemkeOptions dense;
  dense.product_form = false;
  int compared = 0;
  const auto compare = [&](const LcpProblem& p, const std::string& what, bool unique_solution = true) {
    const LcpResult a = solveLemke(p, ws_product);
    const LcpResult b = solveLemke(p, ws_dense, dense);
    ASSERT_EQ(a.status, b.status) << what;
    if (b.status != LcpStatus::Solved) return;
    if (unique_solution) {
      EXPECT_EQ(a.pivots, b.pivots) << what;
      const double scale = std::max(1.0, b.z.lpNorm<Eigen::Infinity>());
      EXPECT_LE((a.z - b.z).lpNorm<Eigen::Infinity>(), 1e-8 * scale) << what;
    } else {
      expectSolved(a);
      expectSolved(b);
      const Eigen::VectorXd wa = p.M * a.z + p.q, wb = p.M * b.z + p.q;
      const double scale = std::max(1.0, wb.lpNorm<Eigen::Infinity>());
      EXPECT_LE((wa - wb).lpNorm<Eigen::Infinity>(), 1e-8 * scale) << what;
    }
    ++compared;
  };
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    for (Index n : {10, 60, 200})
      compare(gen::makeContactLike(n, seed).lcp, "contact-like n=" + std::to_string(n), n <= 42);
    compare(gen::makeSpd(25, seed), "spd");
    compare(gen::makePMatrix(25, seed), "P");
    LcpProblem d = psdWithSolution(8, 3, seed);
    d.q.head(3).setZero();  // degenerate: zeros in q
    compare(d, "zeros in q");
    LcpProblem rep = psdWithSolution(8, 3, seed);
    rep.M.row(1) = rep.M.row(0);  // repeated rows
    rep.M.col(1) = rep.M.col(0);
    rep.q[1] = rep.q[0];
    compare(rep, "repeated rows");
  }
  EXPECT_GE(compared, 30);
}

// M given as an operator (M = A Aᵀ, never formed: columns A (Aᵀ e_j), products A (Aᵀ z)): the same
// pivots and z as the dense M, in the product form and in the dense form (which reads every column)
TEST(Lemke, OperatorAgreesWithDenseMatrix) {
  class Gram final : public LcpMatrixOperator {
   public:
    explicit Gram(const Eigen::MatrixXd& A) : A_(A) {}
    Index size() const override { return A_.rows(); }
    void column(Index j, Eigen::Ref<Eigen::VectorXd> out) const override { out.noalias() = A_ * A_.row(j).transpose(); }
    void multiply(const VectorView& z, Eigen::Ref<Eigen::VectorXd> out) const override {
      out.noalias() = A_ * (A_.transpose() * z);
    }
    double maxAbs() const override { return A_.rowwise().squaredNorm().maxCoeff(); }

   private:
    const Eigen::MatrixXd& A_;
  };
  int compared = 0;
  for (const bool product : {true, false}) {
    LemkeOptions opt;
    opt.product_form = product;
    for (std::uint32_t seed = 1; seed <= 4; ++seed) {
      for (Index n : {12, 80, 200}) {
        const auto c = gen::makeContactLike(n, seed);
        LemkeWorkspace ws_dense, ws_op;
        LcpResult dense, op;
        dense.reserve(n);
        op.reserve(n);
        const Eigen::MatrixXd M = c.A * c.A.transpose();
        ASSERT_EQ(solveLemke(M, c.lcp.q, ws_dense, opt, dense), LcpStatus::Solved) << dense.message;
        ASSERT_EQ(solveLemke(Gram(c.A), c.lcp.q, ws_op, opt, op), LcpStatus::Solved) << op.message;
        EXPECT_EQ(op.pivots, dense.pivots) << "n = " << n;
        const double scale = std::max(1.0, dense.z.head(n).lpNorm<Eigen::Infinity>());
        EXPECT_LE((op.z.head(n) - dense.z.head(n)).lpNorm<Eigen::Infinity>(), 1e-8 * scale) << "n = " << n;
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 24);
}

// a path longer than the eta file (max_etas = 3 on contact-like problems of ~20 pivots): the product
// form restarts in the dense form and ends on the dense form's answer; its pivot count includes the
// abandoned product-form pivots
TEST(Lemke, ProductFormRestartsDenseWhenItsEtaFileIsFull) {
  int restarted = 0;
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    const auto c = gen::makeContactLike(60, seed);
    LemkeWorkspace ws_product, ws_dense;
    LemkeOptions small, dense;
    small.max_etas = 3;
    dense.product_form = false;
    const LcpResult b = solveLemke(c.lcp, ws_dense, dense);
    ASSERT_EQ(b.status, LcpStatus::Solved) << b.message;
    const LcpResult a = solveLemke(c.lcp, ws_product, small);
    ASSERT_EQ(a.status, LcpStatus::Solved) << a.message;
    if (b.pivots <= 3) continue;  // the eta file was enough
    ++restarted;
    EXPECT_EQ(a.pivots, b.pivots + 3);  // 3 etas, the 4th pivot overflows and is not counted
    EXPECT_LE((a.z - b.z).lpNorm<Eigen::Infinity>(), 1e-12 * std::max(1.0, b.z.lpNorm<Eigen::Infinity>()));
  }
  EXPECT_GE(restarted, 3);
}

namespace {
std::vector<std::uint8_t> basisOf(const LemkeWorkspace& ws, Index n) { return {ws.basis(), ws.basis() + n}; }
}  // namespace

// Warm start (solveLemkeWarm): given the basis of a problem's own answer, the answer comes back with
// 0 pivots and the same z; the basis of a nearby problem (q moved a little, as between two steps)
// is accepted when it is still the answer's, and whatever the guess, the answer passes the same
// check as a cold solve
TEST(LemkeWarm, OwnBasisAnswersAtOncePerturbedQStillSolves) {
  int accepted_nearby = 0, cases = 0;
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    for (const Index n : {8, 40, 120}) {
      const auto c = gen::makeContactLike(n, seed);
      const Eigen::MatrixXd M = c.A * c.A.transpose();
      const DenseOperator op(M);
      LemkeWorkspace ws;
      LcpResult cold, warm;
      cold.reserve(n);
      warm.reserve(n);
      ASSERT_EQ(solveLemke(op, c.lcp.q, ws, LemkeOptions{}, cold), LcpStatus::Solved) << cold.message;
      const std::vector<std::uint8_t> basis = basisOf(ws, n);
      bool used = false;
      ASSERT_EQ(solveLemkeWarm(op, c.lcp.q, basis.data(), ws, LemkeOptions{}, warm, &used), LcpStatus::Solved);
      EXPECT_TRUE(used) << "n " << n << " seed " << seed;
      EXPECT_EQ(warm.pivots, 0);
      const double scale = std::max(1.0, cold.z.head(n).lpNorm<Eigen::Infinity>());
      EXPECT_LE((warm.z.head(n) - cold.z.head(n)).lpNorm<Eigen::Infinity>(), 1e-8 * scale);
      // the free velocity moved a little (q = A v_free + d, d ≥ 0, as the next step of a simulation):
      // the same basis usually still answers; either way the answer is one
      std::mt19937 rng(seed);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      Eigen::VectorXd dv(c.A.cols());
      for (Index i = 0; i < dv.size(); ++i) dv[i] = 1e-4 * u(rng);
      const Eigen::VectorXd q2 = c.lcp.q + c.A * dv;
      ASSERT_EQ(solveLemkeWarm(op, q2, basis.data(), ws, LemkeOptions{}, warm, &used), LcpStatus::Solved);
      EXPECT_TRUE(isComplementary(warm.residuals, 1e-9));
      accepted_nearby += used ? 1 : 0;
      ++cases;
    }
  }
  // a small move of q keeps most bases (not all: an entry at 0 may change sides)
  EXPECT_GE(accepted_nearby, cases / 2);
}

// a wrong guess (every z basic, no z basic, the complement of the answer's basis) and a singular
// one (two identical rows both basic) fall back to Lemke: Solved, the cold answer's quality
TEST(LemkeWarm, WrongOrSingularGuessFallsBackToLemke) {
  const Index n = 30;
  auto c = gen::makeContactLike(n, 11);
  c.A.row(5) = c.A.row(4);  // rows 4 and 5 identical: M singular on {4, 5}
  const Eigen::MatrixXd M = c.A * c.A.transpose();
  Eigen::VectorXd q = c.lcp.q;
  q[4] = q[5] = -1.0;
  const DenseOperator op(M);
  LemkeWorkspace ws;
  LcpResult cold, warm;
  cold.reserve(n);
  warm.reserve(n);
  ASSERT_EQ(solveLemke(op, q, ws, LemkeOptions{}, cold), LcpStatus::Solved) << cold.message;
  std::vector<std::uint8_t> complement = basisOf(ws, n);
  for (auto& b : complement) b = b != 0 ? 0 : 1;
  std::vector<std::uint8_t> singular(static_cast<std::size_t>(n), 0);
  singular[4] = singular[5] = 1;
  std::vector<std::uint8_t> all(static_cast<std::size_t>(n), 1);
  std::vector<std::uint8_t> none(static_cast<std::size_t>(n), 0);
  for (const std::vector<std::uint8_t>* guess : {&complement, &singular, &all, &none}) {
    bool used = true;
    ASSERT_EQ(solveLemkeWarm(op, q, guess->data(), ws, LemkeOptions{}, warm, &used), LcpStatus::Solved) << warm.message;
    EXPECT_FALSE(used);
    EXPECT_GT(warm.pivots, 0);
    EXPECT_TRUE(isComplementary(warm.residuals, 1e-9));
    // M is PSD: every answer has the same w
    EXPECT_LE((warm.w.head(n) - cold.w.head(n)).lpNorm<Eigen::Infinity>(), 1e-8 * (1.0 + q.lpNorm<Eigen::Infinity>()));
  }
  // no guess at all: Lemke
  bool used = true;
  ASSERT_EQ(solveLemkeWarm(op, q, nullptr, ws, LemkeOptions{}, warm, &used), LcpStatus::Solved);
  EXPECT_FALSE(used);
  EXPECT_EQ(warm.pivots, cold.pivots);
}

// a nonsymmetric LCP with friction's structure (the Stewart–Trinkle cone rows of the constraint
// solver: w_γ = μλ − Σβ, w_edge = … + γ): its own basis, degenerate entries included, answers at once
TEST(LemkeWarm, FrictionStructureDegenerateBasis) {
  // one contact, 4 edges, a unit Delassus block on (λ, β1..β4) from a normal n and tangents ±t1, ±t2
  // of a point of mass 1 pushed into the plane and sideways, μ = 0.5: sticking
  const Index n = 6;  // λ, β1..β4, γ
  Eigen::MatrixXd R(5, 3);
  R << 0, 0, 1,  1, 0, 0,  0, 1, 0,  -1, 0, 0,  0, -1, 0;
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  M.topLeftCorner(5, 5) = R * R.transpose();
  M(5, 0) = 0.5;
  for (Index k = 1; k <= 4; ++k) {
    M(5, k) = -1.0;
    M(k, 5) = 1.0;
  }
  Eigen::VectorXd q(n);
  const Eigen::Vector3d v_free(0.1, 0.05, -1.0);  // into the plane, a little sideways
  q.head(5) = R * v_free;
  q[5] = 0.0;
  const DenseOperator op(M);
  LemkeWorkspace ws;
  LcpResult cold, warm;
  cold.reserve(n);
  warm.reserve(n);
  ASSERT_EQ(solveLemke(op, q, ws, LemkeOptions{}, cold), LcpStatus::Solved) << cold.message;
  // sticking: the point stops (R q̇ = 0 on the normal and every edge), friction inside the cone
  const Eigen::Vector3d f = R.transpose() * cold.z.head(5);
  EXPECT_NEAR(f.z(), 1.0, 1e-12);
  EXPECT_NEAR(f.x(), -0.1, 1e-12);
  EXPECT_NEAR(f.y(), -0.05, 1e-12);
  const std::vector<std::uint8_t> basis = basisOf(ws, n);
  bool used = false;
  ASSERT_EQ(solveLemkeWarm(op, q, basis.data(), ws, LemkeOptions{}, warm, &used), LcpStatus::Solved);
  EXPECT_TRUE(used);
  EXPECT_LE((R.transpose() * (warm.z.head(5) - cold.z.head(5))).norm(), 1e-12);
}

// a second guess (solveLemkeWarm's overload) is tried when the first fails, before Lemke: the
// answer's own basis as the second guess answers at once; two wrong guesses fall back to Lemke
TEST(LemkeWarm, SecondGuessIsTriedBeforeLemke) {
  const Index n = 30;
  const auto c = gen::makeContactLike(n, 5);
  const Eigen::MatrixXd M = c.A * c.A.transpose();
  const Eigen::VectorXd& q = c.lcp.q;
  const DenseOperator op(M);
  LemkeWorkspace ws;
  LcpResult cold, warm;
  cold.reserve(n);
  warm.reserve(n);
  ASSERT_EQ(solveLemke(op, q, ws, LemkeOptions{}, cold), LcpStatus::Solved) << cold.message;
  ASSERT_GT(cold.pivots, 0);
  const std::vector<std::uint8_t> right = basisOf(ws, n);
  std::vector<std::uint8_t> wrong = right;
  for (auto& b : wrong) b = b != 0 ? 0 : 1;
  bool used = false;
  ASSERT_EQ(solveLemkeWarm(op, q, wrong.data(), right.data(), ws, LemkeOptions{}, warm, &used), LcpStatus::Solved);
  EXPECT_TRUE(used);
  EXPECT_EQ(warm.pivots, 0);
  EXPECT_NE(std::string(warm.message).find("second guess"), std::string::npos) << warm.message;
  EXPECT_LE((warm.z.head(n) - cold.z.head(n)).lpNorm<Eigen::Infinity>(), 1e-9 * (1.0 + cold.z.lpNorm<Eigen::Infinity>()));
  EXPECT_EQ(basisOf(ws, n), right);  // the basis kept is the one that answered
  // the right one first: the second is not needed
  ASSERT_EQ(solveLemkeWarm(op, q, right.data(), wrong.data(), ws, LemkeOptions{}, warm, &used), LcpStatus::Solved);
  EXPECT_TRUE(used);
  EXPECT_NE(std::string(warm.message).find("guessed basis"), std::string::npos) << warm.message;
  // both wrong: Lemke from the start, same answer
  ASSERT_EQ(solveLemkeWarm(op, q, wrong.data(), wrong.data(), ws, LemkeOptions{}, warm, &used), LcpStatus::Solved);
  EXPECT_FALSE(used);
  EXPECT_EQ(warm.pivots, cold.pivots);
  EXPECT_LE((warm.w.head(n) - cold.w.head(n)).lpNorm<Eigen::Infinity>(), 1e-8 * (1.0 + q.lpNorm<Eigen::Infinity>()));
}
