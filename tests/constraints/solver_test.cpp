// The row-based constraint solver on systems checkable by hand (points of mass m, b = (m/τ) I):
// contact, friction cone, two systems, bilateral rows, the fallback chain and the capacity.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>

#include "point_system.hpp"

using namespace mannequin::constraints;
namespace lcp = mannequin::lcp;
using test::PlaneProducer;
using test::PointSystem;

namespace {

constexpr double kG = 9.81;

// rows written by a lambda (tests only)
class FnProducer final : public RowProducer {
 public:
  explicit FnProducer(std::function<void(int, double, RowSet&)> f) : f_(std::move(f)) {}
  const char* name() const override { return "fn"; }
  void addRows(int id, double dt, RowSet& rows) override { f_(id, dt, rows); }

 private:
  std::function<void(int, double, RowSet&)> f_;
};

Eigen::VectorXd gravity(const PointSystem& p) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(p.nv());
  for (int i = p.dim_ - 1; i < p.nv(); i += p.dim_) f[i] = -p.m_ * kG;
  return f;
}

}  // namespace

// b q̇ = m g + Jᵀλ. Before contact q̇_z = −τ g; the first step where the fall would cross z = 0 needs
// λ = b (τ g − d/δt) (it lands exactly on the plane); at rest q̇ = 0 so λ = m g.
TEST(ConstraintSolver, FallingPointStopsOnThePlane) {
  const double m = 2.0, tau = 0.1, dt = 0.01, h0 = 0.045;
  PointSystem p(3, 1, m, tau);
  p.x[2] = h0;
  PlaneProducer plane(p, 0, Eigen::Vector3d::UnitZ());
  ConstraintSolver solver({&p});
  solver.addProducer(&plane);
  bool contacted = false;
  int first_contact_step = -1;
  for (int k = 0; k < 40; ++k) {
    p.freeMotion(gravity(p));
    const double d = p.x[2];
    const SolveReport& rep = solver.solve(dt);
    ASSERT_EQ(rep.solver, SolverUsed::kLemke);
    ASSERT_FALSE(rep.fallback);
    EXPECT_EQ(rep.rows, 1);
    EXPECT_EQ(rep.lcp_size, 1);
    if (!contacted && plane.lambda > 0) {
      contacted = true;
      first_contact_step = k;
      EXPECT_NEAR(plane.lambda, p.b() * (tau * kG - d / dt), 1e-9);
    } else if (!contacted) {
      EXPECT_EQ(plane.lambda, 0.0);
    }
    p.integrate(dt);
    EXPECT_GE(p.x[2], -1e-12) << "step " << k;
    if (contacted && k > first_contact_step) {
      EXPECT_NEAR(plane.lambda, m * kG, 1e-9) << "at rest, step " << k;
      EXPECT_NEAR(p.qdot[2], 0.0, 1e-12);
      EXPECT_EQ(rep.active, 1);
    }
  }
  // h0 = 0.045, falls τ g δt = 0.00981 m per step: the fifth step (k = 4) lands
  EXPECT_EQ(first_contact_step, 4);
  EXPECT_NEAR(p.x[2], 0.0, 1e-12);
  // Γ = Jᵀλ went to the system
  EXPECT_NEAR(p.applied[2], m * kG, 1e-9);
  EXPECT_EQ(solver.failures(), 0);
}

// On a slope of 20° (normal tilted about y) at rest: sticking needs friction m g sin20 ≤ μ m g cos20,
// i.e. μ ≥ tan 20° = 0.364. μ = 0.8 sticks (friction = m g sin20, λ = m g cos20); μ = 0.2 slides
// down with friction μλ (t1 is a cone edge for m = 4 and 8), so b v_t = −m g sin20 + μ m g cos20.
TEST(ConstraintSolver, FrictionConeOnASlope) {
  const double m = 3.0, tau = 0.05, dt = 0.005, a = 20.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d n(-std::sin(a), 0.0, std::cos(a));
  for (const int edges : {4, 8}) {
    for (const double mu : {0.8, 0.2}) {
      SCOPED_TRACE(::testing::Message() << "edges " << edges << " mu " << mu);
      PointSystem p(3, 1, m, tau);
      PlaneProducer plane(p, 0, n, mu, edges);
      SolverOptions o;
      o.max_rows = 4;
      o.max_friction_rows = 2;
      o.max_edges = 8;
      ConstraintSolver solver({&p}, o);
      solver.addProducer(&plane);
      for (int k = 0; k < 50; ++k) {
        p.freeMotion(gravity(p));
        const SolveReport& rep = solver.solve(dt);
        ASSERT_EQ(rep.solver, SolverUsed::kLemke) << lcp::statusName(rep.lemke_status);
        EXPECT_EQ(rep.lcp_size, 1 + edges + 1);
        const double vt = plane.t1().dot(p.qdot.head<3>());
        EXPECT_NEAR(plane.normal().dot(p.qdot.head<3>()), 0.0, 1e-9);  // stays on the plane
        EXPECT_NEAR(plane.lambda, m * kG * std::cos(a), 1e-9);
        EXPECT_LE(plane.friction, mu * plane.lambda * (1 + 1e-12) + 1e-12);  // inside the cone
        EXPECT_NEAR(p.qdot[1], 0.0, 1e-9);  // nothing sideways
        if (mu == 0.8) {
          EXPECT_NEAR(vt, 0.0, 1e-9);
          EXPECT_NEAR(plane.friction, m * kG * std::sin(a), 1e-9);
        } else {
          EXPECT_NEAR(vt, -(tau / m) * (m * kG * std::sin(a) - mu * m * kG * std::cos(a)), 1e-9);
          EXPECT_NEAR(plane.friction, mu * plane.lambda, 1e-9);
        }
        p.integrate(dt);
      }
      if (mu == 0.8) {
        EXPECT_NEAR(p.x.norm(), 0.0, 1e-9);
      } else {
        EXPECT_LT(plane.t1().dot(p.x.head<3>()), -0.01);  // slid down the slope
      }
    }
  }
}

// A row between two systems: Γ_a = J_aᵀλ and Γ_b = J_bᵀλ with J_a = −J_b: equal and opposite.
// Point a pushed up (+F), point b pushed down (−F) at gap 0: λ solves q̇_b,z − q̇_a,z = 0,
// λ = (v_a − v_b)/(1/b_a + 1/b_b) with v = b⁻¹F.
TEST(ConstraintSolver, TwoSystemsGetEqualAndOppositeForces) {
  for (const int dim : {3, 2}) {
    SCOPED_TRACE(dim);
    PointSystem a(dim, 1, 1.0, 0.1), b(dim, 1, 5.0, 0.2);
    const int z = dim - 1;
    ConstraintSolver solver({&a, &b});
    FnProducer touch([&](int id, double, RowSet& rows) {
      RowInfo in;
      in.producer = id;
      in.distance = b.x[z] - a.x[z];
      in.system_a = 0;
      in.system_b = 1;
      const int r = rows.add(in);
      rows.jacobian(r, 0)[z] = -1.0;
      rows.jacobian(r, 1)[z] = 1.0;
    });
    solver.addProducer(&touch);
    Eigen::VectorXd fa = Eigen::VectorXd::Zero(dim), fb = Eigen::VectorXd::Zero(dim);
    fa[z] = 30.0;
    fa[0] = 2.0;  // a tangential push is not resisted (frictionless)
    fb[z] = -10.0;
    a.freeMotion(fa);
    b.freeMotion(fb);
    const SolveReport& rep = solver.solve(0.01);
    ASSERT_EQ(rep.solver, SolverUsed::kLemke);
    const double lambda = solver.rows().info(0).lambda;
    EXPECT_NEAR(lambda, (30.0 / a.b() + 10.0 / b.b()) / (1 / a.b() + 1 / b.b()), 1e-9);
    EXPECT_LT((a.applied + b.applied).norm(), 1e-12);  // Newton's third law
    EXPECT_NEAR(a.applied[z], -lambda, 1e-12);
    EXPECT_NEAR(a.qdot[z], b.qdot[z], 1e-12);
    EXPECT_NEAR(a.qdot[0], 2.0 / a.b(), 1e-12);
    EXPECT_EQ(a.applications, 1);
    EXPECT_EQ(b.applications, 1);
  }
}

// A bilateral row z = h: λ = m g under gravity (pulling up), λ = −F under an upward push F > m g... the
// sign follows the need. The height stays h.
TEST(ConstraintSolver, BilateralRowHoldsAHeight) {
  const double m = 1.5, tau = 0.1, h = 0.3, dt = 0.01;
  for (const double up : {0.0, 40.0}) {
    PointSystem p(3, 1, m, tau);
    p.x[2] = h;
    FnProducer hold([&](int id, double, RowSet& rows) {
      RowInfo in;
      in.kind = RowKind::kBilateral;
      in.source = RowSource::kGrasp;
      in.producer = id;
      in.distance = p.x[2] - h;
      in.system_a = 0;
      rows.jacobian(rows.add(in), 0)[2] = 1.0;
    });
    ConstraintSolver solver({&p});
    solver.addProducer(&hold);
    for (int k = 0; k < 10; ++k) {
      Eigen::VectorXd f = gravity(p);
      f[2] += up;
      p.freeMotion(f);
      const SolveReport& rep = solver.solve(dt);
      ASSERT_EQ(rep.solver, SolverUsed::kLemke);
      EXPECT_EQ(rep.lcp_size, 2);  // the two halves
      EXPECT_NEAR(solver.rows().info(0).lambda, m * kG - up, 1e-9);
      p.integrate(dt);
      EXPECT_NEAR(p.x[2], h, 1e-12);
    }
  }
}

// d < 0 (penetration): the row pushes back at most at recovery_speed.
TEST(ConstraintSolver, PenetrationRecoversAtTheCappedSpeed) {
  PointSystem p(3, 1, 1.0, 0.1);
  p.x[2] = -0.5;
  FnProducer floor([&](int id, double, RowSet& rows) {
    RowInfo in;
    in.producer = id;
    in.distance = p.x[2];
    in.recovery_speed = 0.2;
    in.system_a = 0;
    rows.jacobian(rows.add(in), 0)[2] = 1.0;
  });
  ConstraintSolver solver({&p});
  solver.addProducer(&floor);
  p.freeMotion(gravity(p));
  solver.solve(0.01);
  EXPECT_NEAR(p.qdot[2], 0.2, 1e-12);  // not 50 m/s
}

// Lemke limited to one pivot fails (pivot_limit): the structured solver answers the same
// frictionless problem; with every solver's check impossible, nothing is applied.
TEST(ConstraintSolver, FallbackChain) {
  const double m = 2.0, tau = 0.1;
  PointSystem p(3, 1, m, tau);
  PlaneProducer plane(p, 0, Eigen::Vector3d::UnitZ(), 0.5, 4);
  SolverOptions o;
  o.lemke.max_pivots = 1;
  ConstraintSolver solver({&p}, o);
  solver.addProducer(&plane);
  p.freeMotion(gravity(p));
  const SolveReport& rep = solver.solve(0.01);
  EXPECT_TRUE(rep.fallback);
  EXPECT_EQ(rep.lemke_status, lcp::LcpStatus::PivotLimit);
  EXPECT_EQ(rep.solver, SolverUsed::kStructured);
  EXPECT_EQ(rep.lcp_size, 1);  // frictionless: the normal only
  EXPECT_NEAR(plane.lambda, m * kG, 1e-9);
  EXPECT_EQ(plane.friction, 0.0);
  EXPECT_TRUE(p.qdot.allFinite());
  EXPECT_NEAR(p.qdot[2], 0.0, 1e-12);
  EXPECT_EQ(solver.failures(), 1);
  EXPECT_EQ(solver.unsolved(), 0);

  // structured fails too: PGS answers
  SolverOptions o2 = o;
  o2.structured.check_tolerance = -1.0;  // never passes
  ConstraintSolver pgs_only({&p}, o2);
  pgs_only.addProducer(&plane);
  p.freeMotion(gravity(p));
  EXPECT_EQ(pgs_only.solve(0.01).solver, SolverUsed::kPgs);
  EXPECT_NEAR(plane.lambda, m * kG, 1e-7);

  // every solver fails: nothing applied, counted, no NaN
  SolverOptions o3 = o2;
  o3.pgs.check_tolerance = -1.0;
  o3.pgs.max_iterations = 5;
  ConstraintSolver none({&p}, o3);
  none.addProducer(&plane);
  p.freeMotion(gravity(p));
  p.applications = 0;
  const SolveReport& r3 = none.solve(0.01);
  EXPECT_EQ(r3.solver, SolverUsed::kFailed);
  EXPECT_TRUE(r3.fallback);
  EXPECT_EQ(none.unsolved(), 1);
  EXPECT_EQ(none.failures(), 1);
  EXPECT_EQ(p.applications, 0);
  EXPECT_EQ(p.qdot, p.qdotFree());
  EXPECT_EQ(plane.lambda, 0.0);
  EXPECT_STREQ(solverUsedName(r3.solver), "failed");
}

// A NaN from a producer: every solver rejects it, nothing is applied.
TEST(ConstraintSolver, NanRowIsUnsolvedNotPropagated) {
  PointSystem p(3, 1, 1.0, 0.1);
  FnProducer bad([&](int id, double, RowSet& rows) {
    RowInfo in;
    in.producer = id;
    in.distance = std::nan("");
    rows.jacobian(rows.add(in), 0)[2] = 1.0;
  });
  ConstraintSolver solver({&p});
  solver.addProducer(&bad);
  p.freeMotion(gravity(p));
  EXPECT_EQ(solver.solve(0.01).solver, SolverUsed::kFailed);
  EXPECT_EQ(solver.unsolved(), 1);
  EXPECT_TRUE(p.qdot.allFinite());
  EXPECT_EQ(p.applications, 0);
  // a meaningless δt too
  EXPECT_EQ(solver.solve(0.0).solver, SolverUsed::kFailed);
  EXPECT_EQ(solver.unsolved(), 2);
}

// Rows beyond max_rows (and friction rows beyond max_friction_rows) are dropped and counted.
TEST(ConstraintSolver, RowsBeyondCapacityAreDropped) {
  PointSystem p(3, 6, 1.0, 0.1);
  std::vector<PlaneProducer> planes;
  for (int i = 0; i < 6; ++i) planes.emplace_back(p, 0, Eigen::Vector3d::UnitZ(), i < 3 ? 0.5 : 0.0, i < 3 ? 4 : 0, i);
  SolverOptions o;
  o.max_rows = 4;
  o.max_friction_rows = 2;
  ConstraintSolver solver({&p}, o);
  for (auto& pl : planes) solver.addProducer(&pl);
  p.freeMotion(gravity(p));
  const SolveReport& rep = solver.solve(0.01);
  EXPECT_EQ(rep.rows, 4);
  EXPECT_EQ(rep.dropped, 2);  // the third friction row, and the sixth row
  EXPECT_EQ(planes[2].row, -1);
  EXPECT_EQ(planes[5].row, -1);
  EXPECT_EQ(rep.solver, SolverUsed::kLemke);
  EXPECT_EQ(rep.lcp_size, 4 + 2 * (4 + 1));
  for (int i : {0, 1, 3, 4}) EXPECT_NEAR(planes[static_cast<std::size_t>(i)].lambda, kG, 1e-9);
  EXPECT_EQ(solver.solve(0.01).dropped, 4);  // since construction
  EXPECT_STREQ(rowSourceName(RowSource::kContact), "contact");
}

TEST(ConstraintSolver, RejectsBadConstruction) {
  PointSystem p(3, 1, 1.0, 0.1);
  EXPECT_THROW(ConstraintSolver({}), std::invalid_argument);
  EXPECT_THROW(ConstraintSolver({nullptr}), std::invalid_argument);
  SolverOptions o;
  o.max_friction_rows = o.max_rows + 1;
  EXPECT_THROW(ConstraintSolver({&p}, o), std::invalid_argument);
}

// Many dense rows (more than one 64-column assembly panel) on two systems of nv = 42: whichever solver
// answers, the velocities the systems end with satisfy the LCP row by row, computed independently of
// the solver's M: w_r = J_r q̇ + max(d_r/δt, −v) ≥ 0, λ_r ≥ 0, w_r λ_r = 0.
// (d ≥ 0, so stopping both systems satisfies every row: the LCP has a solution.)
TEST(ConstraintSolver, ManyDenseRowsAreComplementary) {
  PointSystem a(3, 14, 60.0, 0.1), b(3, 14, 20.0, 0.05);
  const int n = 150;
  const double dt = 0.01;
  std::vector<Eigen::VectorXd> Ja(n), Jb(n);
  std::vector<double> d(n);
  for (int i = 0; i < n; ++i) {
    Ja[static_cast<std::size_t>(i)] = Eigen::VectorXd::Zero(42);
    Jb[static_cast<std::size_t>(i)] = Eigen::VectorXd::Zero(42);
    for (int j = 0; j < 42; ++j) {
      if (i % 3 != 2) Ja[static_cast<std::size_t>(i)][j] = std::sin(0.7 * i + 1.3 * j);
      if (i % 3 != 0) Jb[static_cast<std::size_t>(i)][j] = std::cos(0.4 * i - 0.8 * j);
    }
    d[static_cast<std::size_t>(i)] = 0.0002 * (1.0 + std::sin(2.1 * i));  // ≥ 0: q̇ = 0 is feasible
  }
  FnProducer dense([&](int id, double, RowSet& rows) {
    for (int i = 0; i < n; ++i) {
      RowInfo in;
      in.producer = id;
      in.distance = d[static_cast<std::size_t>(i)];
      in.recovery_speed = 0.5;
      const int r = rows.add(in);
      if (i % 3 != 2) rows.jacobian(r, 0) = Ja[static_cast<std::size_t>(i)].transpose();
      if (i % 3 != 0) rows.jacobian(r, 1) = Jb[static_cast<std::size_t>(i)].transpose();
    }
  });
  ConstraintSolver solver({&a, &b});
  solver.addProducer(&dense);
  Eigen::VectorXd fa(42), fb(42);
  for (int j = 0; j < 42; ++j) {
    fa[j] = 500.0 * std::cos(0.3 * j);
    fb[j] = -300.0 * std::sin(0.2 * j + 1.0);
  }
  a.freeMotion(fa);
  b.freeMotion(fb);
  const SolveReport& rep = solver.solve(dt);
  ASSERT_NE(rep.solver, SolverUsed::kFailed);
  EXPECT_GT(rep.active, 0);
  double wmin = 0, comp = 0, lmin = 0, lmax = 0;
  int active_past_panel = 0;
  for (int i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const double w = Ja[ui].dot(a.qdot) + Jb[ui].dot(b.qdot) + std::max(d[ui] / dt, -0.5);
    const double l = solver.rows().info(i).lambda;
    wmin = std::min(wmin, w);
    lmin = std::min(lmin, l);
    lmax = std::max(lmax, l);
    comp = std::max(comp, std::abs(w * l));
    active_past_panel += i >= 64 && l > 0 ? 1 : 0;
  }
  EXPECT_GT(active_past_panel, 0);  // the check reaches past the first assembly panel
  EXPECT_GT(wmin, -1e-6);
  EXPECT_GE(lmin, 0.0);
  EXPECT_LT(comp, 1e-6 * (1 + lmax));
  // Γ_s = Σ_r J_{r,s}ᵀ λ_r
  Eigen::VectorXd ga = Eigen::VectorXd::Zero(42);
  for (int i = 0; i < n; ++i) ga += Ja[static_cast<std::size_t>(i)] * solver.rows().info(i).lambda;
  EXPECT_LT((ga - a.applied).norm(), 1e-9 * (1 + ga.norm()));
  std::printf("dense rows: solver %s, lemke %s, lcp %d, active %d, pivots %d, assemble %.1f us, solve %.1f us\n",
              solverUsedName(rep.solver), lcp::statusName(rep.lemke_status), rep.lcp_size, rep.active, rep.pivots,
              rep.assemble_s * 1e6, rep.solve_s * 1e6);
}

namespace {
/// A 2-D point kept inside the unit disk: d = 1 − |x|, J = −xᵀ/|x| (curved: the linear row leaves
/// (δt v_t)²/2 outside when the point slides along the circle at tangential speed v_t). refine()
/// returns the exact distance at the answer's velocity.
class DiskProducer final : public RowProducer {
 public:
  explicit DiskProducer(const PointSystem& sys) : sys_(&sys) {}
  const char* name() const override { return "disk"; }
  void addRows(int id, double /*dt*/, RowSet& rows) override {
    const Eigen::Vector2d x = sys_->x.head<2>();
    RowInfo in;
    in.producer = id;
    in.distance = 1.0 - x.norm();
    in.system_a = 0;
    row_ = rows.add(in);
    if (row_ >= 0) rows.jacobian(row_, 0).head<2>() = -x.normalized();
  }
  bool refine(int /*id*/, double dt, RowSet& rows, const std::vector<Eigen::VectorXd>& velocity) override {
    if (row_ < 0) return false;
    const Eigen::Vector2d x = sys_->x.head<2>(), v = velocity[0].head<2>();
    RowInfo& in = rows.info(row_);
    const double next = 1.0 - (x + dt * v).norm();
    const double c = next - (in.distance + dt * rows.jacobians(0).row(row_).head<2>().dot(v));
    const bool again = std::abs(c - in.correction) > 1e-12;
    in.correction = c;
    ++refines;
    return again;
  }
  int refines = 0;

 private:
  const PointSystem* sys_;
  int row_ = -1;
};

/// Max over 300 steps of how far the point is outside the disk, pushed outwards and along the circle.
double worstDiskExcess(int refine_rounds, int* rounds = nullptr) {
  PointSystem sys(2, 1, 1.0, 1.0);  // b = 1: q̇ = Γ
  sys.x << 0.9, 0.0;
  DiskProducer disk(sys);
  SolverOptions opt;
  opt.refine_rounds = refine_rounds;
  ConstraintSolver solver({&sys}, opt);
  solver.addProducer(&disk);
  const double dt = 0.01;
  double worst = 0.0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector2d r = sys.x.head<2>().normalized(), t(-r.y(), r.x());
    sys.freeMotion(5.0 * t + 2.0 * r);  // 5 m/s along the circle, 2 m/s outwards
    const SolveReport& rep = solver.solve(dt);
    EXPECT_EQ(rep.solver, SolverUsed::kLemke);
    if (rounds) *rounds = std::max(*rounds, rep.refine_rounds);
    sys.integrate(dt);
    worst = std::max(worst, sys.x.head<2>().norm() - 1.0);
  }
  return worst;
}
}  // namespace

TEST(ConstraintSolver, RefinementKeepsACurvedRowAtTheNextStepNotOnlyToFirstOrder) {
  // first order: sliding at 5 m/s along the unit circle leaves ≈ (δt v)²/2 = 1.25e-3 m outside
  const double linear = worstDiskExcess(0);
  EXPECT_GT(linear, 1e-3);
  EXPECT_LT(linear, 1.5e-3);
  // refined: the exact distance at the answer's velocity; the fixed point contracts by ~δt v/R = 0.05
  // per round, so a few rounds reach the producer's 1e-12
  int rounds = 0;
  const double refined = worstDiskExcess(6, &rounds);
  EXPECT_LT(refined, 1e-10);
  EXPECT_GE(rounds, 1);
  EXPECT_LE(rounds, 6);
  std::printf("disk: worst excess %.3g m first order, %.3g m refined (at most %d rounds)\n", linear, refined, rounds);
}

// Warm start (SolverOptions::warm_start): from the second step on, the previous step's basis answers
// the LCP of a box at rest or sliding on a slope with 0 pivots, and the motion is the cold solver's
TEST(ConstraintSolver, WarmStartAnswersSteadyStepsWithTheColdMotion) {
  const double m = 3.0, tau = 0.05, dt = 0.005, a = 20.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d n(-std::sin(a), 0.0, std::cos(a));
  for (const double mu : {0.8, 0.2}) {
    SCOPED_TRACE(::testing::Message() << "mu " << mu);
    PointSystem warm_p(3, 1, m, tau), cold_p(3, 1, m, tau);
    PlaneProducer warm_plane(warm_p, 0, n, mu, 4), cold_plane(cold_p, 0, n, mu, 4);
    SolverOptions o;
    o.max_rows = 4;
    o.max_friction_rows = 2;
    SolverOptions oc = o;
    oc.warm_start = false;
    ConstraintSolver warm({&warm_p}, o), cold({&cold_p}, oc);
    warm.addProducer(&warm_plane);
    cold.addProducer(&cold_plane);
    int answered = 0;
    for (int k = 0; k < 40; ++k) {
      warm_p.freeMotion(gravity(warm_p));
      cold_p.freeMotion(gravity(cold_p));
      const SolveReport& rw = warm.solve(dt);
      const SolveReport& rc = cold.solve(dt);
      ASSERT_EQ(rw.solver, SolverUsed::kLemke);
      ASSERT_EQ(rc.solver, SolverUsed::kLemke);
      EXPECT_EQ(rc.warm, 0);
      EXPECT_EQ(rw.lcp_solves, 1);
      if (k == 0) {
        EXPECT_EQ(rw.warm, 0);  // nothing to start from
      }
      if (rw.warm == 1) {
        EXPECT_EQ(rw.pivots, 0);
        ++answered;
      }
      EXPECT_LE((warm_p.qdot - cold_p.qdot).lpNorm<Eigen::Infinity>(), 1e-12) << "step " << k;
      EXPECT_NEAR(warm_plane.lambda, cold_plane.lambda, 1e-9);
      EXPECT_NEAR(warm_plane.friction, cold_plane.friction, 1e-9);
      warm_p.integrate(dt);
      cold_p.integrate(dt);
    }
    EXPECT_EQ(answered, 39);  // every step after the first
  }
}
