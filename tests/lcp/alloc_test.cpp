// Allocation counting: the solve path allocates a fixed number of blocks per call (result
// vectors), never per pivot / sweep / active-set step. Allocations are counted by
// tests/common/alloc_counter.hpp (malloc interposed; under AddressSanitizer its allocator hook).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mannequin/lcp/lemke.hpp"
#include "mannequin/lcp/pgs.hpp"
#include "mannequin/lcp/structured.hpp"
#include "mannequin/lcp/testing.hpp"
#include "../common/alloc_counter.hpp"
#include "../common/no_eigen_malloc.hpp"

using namespace mannequin::lcp;

TEST(Allocation, LemkeDoesNotAllocatePerPivot) {
  if (!allocationsCountable()) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  const Index n = 60;
  const LcpProblem many = gen::makeSpd(n, 3);
  LcpProblem few = many;
  few.q.setOnes();
  few.q[0] = -1.0;
  LemkeWorkspace ws(n);
  LcpResult a, b;
  const long na = countAllocations([&] { a = solveLemke(few, ws); });
  const long nb = countAllocations([&] { b = solveLemke(many, ws); });
  ASSERT_EQ(a.status, LcpStatus::Solved);
  ASSERT_EQ(b.status, LcpStatus::Solved);
  EXPECT_LE(a.pivots, 2);
  EXPECT_GE(b.pivots, 20);
  EXPECT_GT(na, 0);  // the counter sees the result vectors, so it is live
  EXPECT_EQ(na, nb);
}

// the in-place form for a real-time loop: nothing at all once the result and the workspace have
// size n, whatever the path (pivots, ray and retries); under NoEigenMalloc when the build checks it
TEST(Allocation, LemkeInPlaceAllocatesNothing) {
  if (!allocationsCountable()) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  const Index n = 40;
  const LcpProblem spd = gen::makeSpd(n, 3);
  LcpProblem trivial = spd;
  trivial.q.setOnes();
  // PSD with a ray (rows 0 and 1 opposite, both distances negative): NoSolution after the retries
  auto c = gen::makeContactLike(n, 7);
  c.A.row(1) = -c.A.row(0);
  LcpProblem ray{c.A * c.A.transpose(), c.lcp.q};
  ray.q[0] = -0.01;
  ray.q[1] = -0.01;
  // both forms of the pivoting (product form, the default, and the dense tableau)
  for (const bool product : {true, false}) {
    LemkeOptions opt;
    opt.product_form = product;
    LemkeWorkspace ws(n);
    LcpResult r;
    solveLemke(ray, ws, opt, r);  // warm-up: sizes the result and the retry result
    for (const LcpProblem* p : std::initializer_list<const LcpProblem*>{&spd, &trivial, &ray}) {
      LcpStatus status = LcpStatus::Invalid;
      const long allocations = countAllocations([&] {
        const NoEigenMalloc no_eigen_malloc;
        status = solveLemke(*p, ws, opt, r);
      });
      EXPECT_EQ(allocations, 0) << statusName(status) << (product ? " (product form)" : " (dense)");
      EXPECT_EQ(status, r.status);
      EXPECT_EQ(status, p == &ray ? LcpStatus::NoSolution : LcpStatus::Solved) << r.message;
      // same answer as the allocating form
      const LcpResult fresh = solveLemke(*p, ws, opt);
      EXPECT_EQ(fresh.status, r.status);
      EXPECT_EQ(fresh.pivots, r.pivots);
      EXPECT_EQ((fresh.z - r.z).lpNorm<Eigen::Infinity>(), 0.0);
    }
  }
}

TEST(Allocation, PgsAndStructuredDoNotAllocatePerStep) {
  if (!allocationsCountable()) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  const auto c = gen::makeContactLike(120, 5);
  LcpProblem few = c.lcp;
  few.q.setConstant(0.01);
  few.q[3] = -0.01;
  StructuredWorkspace sw(120, c.A.cols());
  StructuredOptions so;
  so.warm_start = false;
  LcpResult a, b;
  const long na = countAllocations([&] { a = solveStructured(StructuredProblem{c.A, few.q}, sw, so); });
  const long nb = countAllocations([&] { b = solveStructured(StructuredProblem{c.A, c.lcp.q}, sw, so); });
  ASSERT_EQ(a.status, LcpStatus::Solved);
  ASSERT_EQ(b.status, LcpStatus::Solved);
  EXPECT_LT(a.pivots, b.pivots);
  EXPECT_EQ(na, nb);
  // PGS: 3 sweeps vs 30 sweeps
  const auto spd = gen::makeSpd(50, 2);
  PgsWorkspace pw(50);
  PgsOptions o3, o30;
  o3.max_iterations = 3;
  o30.max_iterations = 30;
  o30.tolerance = 0.0;
  const long p3 = countAllocations([&] { a = solvePgs(spd, pw, o3); });
  const long p30 = countAllocations([&] { b = solvePgs(spd, pw, o30); });
  EXPECT_EQ(a.pivots, 3);
  EXPECT_GE(b.pivots, 20);
  EXPECT_GE(p30, p3);
  EXPECT_LE(p30 - p3, 2);  // a converged sweep may build w once for its residual check
}

// the capacity path: reserved once for the largest size, then problems of varying n (blocks of
// capacity-sized buffers) allocate nothing and answer as the allocating forms do
TEST(Allocation, CapacityPathVaryingSizeAllocatesNothing) {
  if (!allocationsCountable()) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  const Index cap = 50;
  const auto c = gen::makeContactLike(cap, 5);  // A cap×m, M = A Aᵀ
  const Index m = c.A.cols();
  LemkeWorkspace lw;
  PgsWorkspace pw;
  StructuredWorkspace sw;
  lw.reserve(cap);
  pw.reserve(cap);
  sw.reserve(cap, m);
  LcpResult r;
  r.reserve(cap);
  PgsOptions po;
  po.max_iterations = 20000;
  StructuredOptions so;
  so.warm_start = false;
  for (const Index n : {Index{50}, Index{7}, Index{31}, Index{2}, Index{50}, Index{19}}) {
    const auto M = c.lcp.M.topLeftCorner(n, n);
    const auto q = c.lcp.q.head(n);
    LcpStatus ls = LcpStatus::Invalid, ps = LcpStatus::Invalid, ss = LcpStatus::Invalid;
    Eigen::VectorXd zl, zp, zs;
    const long allocations = countAllocations([&] {
      const NoEigenMalloc no_eigen_malloc;
      ls = solveLemke(M, q, lw, LemkeOptions{}, r);
    });
    zl = r.z.head(n);
    const long pgs_allocations = countAllocations([&] { ps = solvePgs(M, q, pw, po, r); });
    zp = r.z.head(n);
    const long structured_allocations = countAllocations([&] { ss = solveStructured(c.A.topRows(n), q, sw, so, r); });
    zs = r.z.head(n);
    EXPECT_EQ(allocations, 0) << "n = " << n;
    EXPECT_EQ(pgs_allocations, 0) << "n = " << n;
    EXPECT_EQ(structured_allocations, 0) << "n = " << n;
    ASSERT_EQ(ls, LcpStatus::Solved) << n;
    ASSERT_EQ(ss, LcpStatus::Solved) << n;
    // the allocating form on a copy of the block gives the same z
    const LcpProblem copy{M, q};
    LemkeWorkspace fresh_ws;
    const LcpResult fresh = solveLemke(copy, fresh_ws);
    EXPECT_EQ((fresh.z - zl).lpNorm<Eigen::Infinity>(), 0.0) << n;
    // w = Mz + q is unique for PSD M: all three agree on it
    const Eigen::VectorXd wl = M * zl + q, ws = M * zs + q;
    EXPECT_LT((wl - ws).lpNorm<Eigen::Infinity>(), 1e-7) << n;
    if (ps == LcpStatus::Solved) {
      EXPECT_LT((wl - (M * zp + q)).lpNorm<Eigen::Infinity>(), 1e-6) << n;
    }
  }
}

// the warm start's path (the guess tried, accepted or not, then Lemke) allocates nothing once the
// workspace has held the largest guess
TEST(Allocation, LemkeWarmStartAllocatesNothing) {
  if (!allocationsCountable()) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  const Index n = 40;
  const auto c = gen::makeContactLike(n, 3);
  const Eigen::MatrixXd M = c.A * c.A.transpose();
  const DenseOperator op(M);
  LemkeWorkspace ws;
  ws.reserve(n);
  LcpResult r;
  r.reserve(n);
  ASSERT_EQ(solveLemke(op, c.lcp.q, ws, LemkeOptions{}, r), LcpStatus::Solved);
  std::vector<std::uint8_t> good(ws.basis(), ws.basis() + n), all(static_cast<std::size_t>(n), 1);
  bool used = false;
  solveLemkeWarm(op, c.lcp.q, all.data(), ws, LemkeOptions{}, r, &used);  // warm-up: the largest guess
  for (const std::vector<std::uint8_t>* guess : {&good, &all, &good}) {
    LcpStatus s = LcpStatus::Invalid;
    const long allocations = countAllocations([&] {
      const NoEigenMalloc no_eigen_malloc;
      s = solveLemkeWarm(op, c.lcp.q, guess->data(), ws, LemkeOptions{}, r, &used);
    });
    EXPECT_EQ(s, LcpStatus::Solved);
    EXPECT_EQ(used, guess == &good);
    EXPECT_EQ(allocations, 0);
  }
}
