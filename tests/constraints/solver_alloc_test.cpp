// solve() allocates nothing after a warm-up at the largest size, while the number of rows (and
// friction rows, and bilateral rows) changes from step to step. Allocations are counted by
// tests/common/alloc_counter.hpp (malloc interposed; under AddressSanitizer its allocator hook): its own executable.
#include <gtest/gtest.h>

#include "point_system.hpp"
#include "../common/alloc_counter.hpp"
#include "../common/no_eigen_malloc.hpp"

using namespace mannequin::constraints;
using test::PointSystem;

namespace {

// `count` rows on two 6-point systems: point i of system (i % 2) on the floor z = 0 (every third
// with a 4-edge cone), and one bilateral row tying the systems' first points when count > 4
class ManyRows final : public RowProducer {
 public:
  ManyRows(const PointSystem& a, const PointSystem& b) : sys_{&a, &b} {}
  const char* name() const override { return "many"; }
  void addRows(int id, double, RowSet& rows) override {
    for (int i = 0; i < count; ++i) {
      const int s = i % 2, pt = (i / 2) % 6;
      RowInfo in;
      in.producer = id;
      in.tag = i;
      in.distance = sys_[s]->x[3 * pt + 2];
      in.system_a = s;
      if (i % 3 == 0) {
        in.mu = 0.5;
        in.friction_edges = 4;
      }
      const int r = rows.add(in);
      if (r < 0) continue;
      rows.jacobian(r, s)[3 * pt + 2] = 1.0;
      if (rows.frictionSlot(r) >= 0) {
        rows.tangent(r, s, 0)[3 * pt] = 1.0;
        rows.tangent(r, s, 1)[3 * pt + 1] = 1.0;
      }
    }
    if (count > 4) {
      RowInfo in;
      in.kind = RowKind::kBilateral;
      in.producer = id;
      in.distance = sys_[1]->x[0] - sys_[0]->x[0];
      in.system_a = 0;
      in.system_b = 1;
      const int r = rows.add(in);
      rows.jacobian(r, 0)[0] = -1.0;
      rows.jacobian(r, 1)[0] = 1.0;
    }
  }
  int count = 0;

 private:
  const PointSystem* sys_[2];
};

}  // namespace

TEST(ConstraintSolverAllocation, VaryingRowCountsAllocateNothingAfterWarmUp) {
  if (!allocationsCountable()) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  PointSystem a(3, 6, 1.0, 0.1), b(3, 6, 2.0, 0.1);
  Eigen::VectorXd fa = Eigen::VectorXd::Zero(18), fb = Eigen::VectorXd::Zero(18);
  for (int i = 0; i < 6; ++i) {
    fa[3 * i + 2] = -9.81;
    fa[3 * i] = 1.0 + i;  // sliding pushes
    fb[3 * i + 2] = -2 * 9.81;
  }
  fb[0] = -3.0;
  ManyRows many(a, b);
  SolverOptions o;
  o.max_rows = 16;
  o.max_friction_rows = 6;
  ConstraintSolver solver({&a, &b}, o);
  solver.addProducer(&many);
  // warm-up at the largest size
  many.count = 12;
  a.freeMotion(fa);
  b.freeMotion(fb);
  ASSERT_EQ(solver.solve(0.01).solver, SolverUsed::kLemke);
  for (const int count : {3, 12, 0, 7, 1, 10, 5, 12, 2}) {
    many.count = count;
    a.freeMotion(fa);
    b.freeMotion(fb);
    SolverUsed used = SolverUsed::kFailed;
    const long allocations = countAllocations([&] {
      const NoEigenMalloc no_eigen_malloc;
      used = solver.solve(0.01).solver;
    });
    EXPECT_EQ(allocations, 0) << "rows " << count;
    EXPECT_EQ(used, count == 0 ? SolverUsed::kNone : SolverUsed::kLemke) << count;
    EXPECT_TRUE(a.qdot.allFinite() && b.qdot.allFinite());
    // every floor row holds: no point goes down
    for (int r = 0; r < solver.rows().size(); ++r) {
      const RowInfo& in = solver.rows().info(r);
      if (in.kind == RowKind::kUnilateral) {
        const PointSystem& s = in.system_a == 0 ? a : b;
        const int pt = (in.tag / 2) % 6;
        EXPECT_GE(s.qdot[3 * pt + 2], -1e-9) << "row " << r;
      }
    }
  }
  EXPECT_EQ(solver.failures(), 0);
}

namespace {

// `count` rows with dense Jacobians on one system of nv = 42 (a mannequin's size), all far from
// their limit (q ≥ 0: Lemke answers z = 0 at once) — the assembly at a realistic size
class DenseRows final : public RowProducer {
 public:
  const char* name() const override { return "dense"; }
  void addRows(int id, double, RowSet& rows) override {
    for (int i = 0; i < count; ++i) {
      RowInfo in;
      in.producer = id;
      in.distance = 10.0;
      in.system_a = 0;
      if (i % 4 == 0) {
        in.mu = 0.5;
        in.friction_edges = 4;
      }
      const int r = rows.add(in);
      if (r < 0) continue;
      auto J = rows.jacobian(r, 0);
      for (int j = 0; j < J.size(); ++j) J[j] = std::sin(0.7 * i + 1.3 * j);
      if (rows.frictionSlot(r) >= 0) {
        auto t1 = rows.tangent(r, 0, 0);
        auto t2 = rows.tangent(r, 0, 1);
        for (int j = 0; j < t1.size(); ++j) {
          t1[j] = std::cos(0.3 * i + 0.9 * j);
          t2[j] = std::cos(0.5 * i - 0.4 * j);
        }
      }
    }
  }
  int count = 0;
};

}  // namespace

TEST(ConstraintSolverAllocation, MannequinSizedAssemblyAllocatesNothing) {
  if (!allocationsCountable()) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  PointSystem p(3, 14, 60.0, 0.1);  // nv = 42
  Eigen::VectorXd f = Eigen::VectorXd::Zero(42);
  DenseRows dense;
  SolverOptions o;  // defaults: 512 rows, 256 with cones
  ConstraintSolver solver({&p}, o);
  solver.addProducer(&dense);
  dense.count = 400;
  p.freeMotion(f);
  ASSERT_EQ(solver.solve(0.01).solver, SolverUsed::kLemke);
  EXPECT_EQ(solver.report().lcp_size, 400 + 100 * 5);
  for (const int count : {37, 400, 211}) {
    dense.count = count;
    p.freeMotion(f);
    SolverUsed used = SolverUsed::kFailed;
    const long allocations = countAllocations([&] { used = solver.solve(0.01).solver; });
    EXPECT_EQ(allocations, 0) << "rows " << count;
    EXPECT_EQ(used, SolverUsed::kLemke);
  }
}
