// Balance of the whole mannequin, variational form (thesis 3.96–3.107, Algorithm 5, Fig. 3.18): the
// 50th-percentile male stands with its soles on the floor (4 points each), reaches a wall in front with
// its left hand, leans on it, and reaches forwards with its right hand while a disturbing-force margin
// asks for robustness to pushes.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "male50_fixture.hpp"
#include "mannequin/balance/variational_balance.hpp"
#include "mannequin/lcp/qp.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin;
using namespace mannequin::balance;
using mannequin::testing_fixture::male50;

namespace {

/// 4 points per sole (heel and toe corners, ±4 cm), on the sole frames' joints.
std::vector<BodyContact> soleContacts(const skeleton::Model& m) {
  std::vector<BodyContact> out;
  for (const char* s : {"sole_l", "sole_r"}) {
    const skeleton::Frame& f = m.frames[static_cast<std::size_t>(m.frameIndex(s))];
    for (double x : {-0.10, 0.11})
      for (double y : {-0.04, 0.04}) out.push_back({f.joint, f.placement.act(math::Vector3(x, y, 0)), {0, 0, 1}, 0.6, {0, 0, 0}});
  }
  return out;
}

struct AlgRun {
  skeleton::VectorX q;
  int steps = 0, failed = 0;
  double worst_contact_drift = 0, worst_residual = 0, min_edge_force = 0;
  double worst_real_moment_residual = 0, worst_real_force_residual = 0;
  VariationalBalanceResult last;
};

/// Runs Algorithm 5 for `steps` steps (q ← q ⊕ δq), tracking the contacts' world points.
AlgRun runAlg5(VariationalBalanceProblem p, skeleton::VectorX q, int steps) {
  const skeleton::Model& m = male50();
  VariationalBalanceSolver solver(m);
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, q);
  std::vector<math::Vector3> start;
  for (const BodyContact& c : p.contacts) start.push_back(d.oMi[static_cast<std::size_t>(c.joint)].act(c.local_point));
  AlgRun run;
  for (int k = 0; k < steps; ++k) {
    const VariationalBalanceResult& r = solver.solve(p, q);
    if (r.status != BalanceStatus::kSolved) {
      ++run.failed;
      run.last = r;
      break;
    }
    // the equilibrium at q_{k+1} with the real CoM (not the linearised one the QP used): the contact
    // forces at their points (q_k) and the weight at the new CoM, Σ p × f + x × m g and Σ f + m g
    std::vector<math::Vector3> points;
    for (const BodyContact& c : p.contacts) points.push_back(d.oMi[static_cast<std::size_t>(c.joint)].act(c.local_point));
    q = skeleton::integrate(m, q, r.dq);
    skeleton::forwardKinematics(m, d, q);
    const math::Vector3 mg = m.totalMass() * p.gravity, com = skeleton::centerOfMass(m, d);
    math::Vector3 moment = com.cross(mg), force = mg;
    for (std::size_t i = 0; i < points.size(); ++i) {
      moment += points[i].cross(r.forces[i]);
      force += r.forces[i];
    }
    run.worst_real_moment_residual = std::max(run.worst_real_moment_residual, moment.cwiseAbs().maxCoeff());
    run.worst_real_force_residual = std::max(run.worst_real_force_residual, force.cwiseAbs().maxCoeff());
    for (std::size_t i = 0; i < p.contacts.size(); ++i)
      run.worst_contact_drift = std::max(run.worst_contact_drift, (d.oMi[static_cast<std::size_t>(p.contacts[i].joint)].act(p.contacts[i].local_point) - start[i]).norm());
    run.worst_residual = std::max(run.worst_residual, r.equilibrium_residual);
    run.min_edge_force = std::min(run.min_edge_force, r.min_raw_edge_force);
    run.last = r;
    ++run.steps;
  }
  run.q = q;
  return run;
}

math::Vector3 framePosition(const skeleton::VectorX& q, const char* frame) {
  skeleton::Data d(male50());
  skeleton::forwardKinematics(male50(), d, q);
  return d.oMf[static_cast<std::size_t>(male50().frameIndex(frame))].p;
}

math::Vector3 comOf(const skeleton::VectorX& q) {
  skeleton::Data d(male50());
  skeleton::forwardKinematics(male50(), d, q);
  return skeleton::centerOfMass(male50(), d);
}

}  // namespace

// Fig. 3.18. Phase 1: the left hand goes to the wall (a task), the soles stay put. Phase 2: the left
// hand is a contact on the wall (normal −x), the right hand reaches forwards and down, with and without
// a margin against ±150 N fore-aft pushes at the CoM. The contact points stay still, the right hand
// reaches its target, and with the margin the mannequin leans further towards the wall and presses it harder.
TEST(VariationalBalance, Fig3_18_ContactsStayTheHandReachesTheMarginLeansOnTheWall) {
  const skeleton::Model& m = male50();
  const skeleton::VectorX q0 = skeleton::standingConfiguration(m);
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, q0);
  const double wall = framePosition(q0, "hand_l").x() + 0.40;
  VariationalBalanceProblem p1;
  p1.contacts = soleContacts(m);
  p1.held = holdCurrentPoses(p1.contacts, d.oMi);
  const math::Vector3 on_wall(wall, framePosition(q0, "hand_l").y() + 0.05, 1.25);
  p1.tasks = {{m.frameIndex("hand_l"), on_wall}};
  const AlgRun reach = runAlg5(p1, q0, 150);
  ASSERT_EQ(reach.failed, 0) << reach.last.message;
  std::printf("phase 1: left hand %.4f m from the wall point, soles drifted %.5f m, %d equality rows, LCP %d\n",
              (framePosition(reach.q, "hand_l") - on_wall).norm(), reach.worst_contact_drift, reach.last.equality_rows,
              reach.last.lcp_size);
  ASSERT_LT((framePosition(reach.q, "hand_l") - on_wall).norm(), 0.005);
  EXPECT_LT(reach.worst_contact_drift, 1e-3);

  // phase 2: the left hand is on the wall
  skeleton::forwardKinematics(m, d, reach.q);
  const skeleton::Frame& hl = m.frames[static_cast<std::size_t>(m.frameIndex("hand_l"))];
  VariationalBalanceProblem p2;
  p2.contacts = soleContacts(m);
  p2.contacts.push_back({hl.joint, hl.placement.p, {-1, 0, 0}, 0.6, {0, 0, 0}});
  p2.held = holdCurrentPoses(p2.contacts, d.oMi);
  const math::Vector3 reach_r = framePosition(reach.q, "hand_r") + math::Vector3(0.25, -0.05, 0.15);
  p2.tasks = {{m.frameIndex("hand_r"), reach_r}};
  const AlgRun plain = runAlg5(p2, reach.q, 200);
  VariationalBalanceProblem p3 = p2;
  const math::Vector3 at = comOf(reach.q);
  for (double sgn : {1.0, -1.0}) {
    const math::Vector3 force(sgn * 150.0, 0, 0);
    math::Vector6 D;
    D << at.cross(force), force;
    p3.force_margins.push_back(D);
  }
  const AlgRun margin = runAlg5(p3, reach.q, 200);
  for (const AlgRun* r : {&plain, &margin}) {
    ASSERT_EQ(r->failed, 0) << r->last.message;
    EXPECT_LT(r->worst_contact_drift, 1e-3) << "contact points stay still";
    EXPECT_LT((framePosition(r->q, "hand_r") - reach_r).norm(), 0.01) << "the right hand reaches its target";
    EXPECT_GE(r->min_edge_force, -1e-9) << "the LCP's own edge forces, before rounding";
    // the QP's equilibrium (3.98) with the linearised CoM holds to rounding; with the real CoM at q_{k+1}
    // the forces balance the weight exactly, and its moment to what the linearisation of the CoM leaves
    // over one step: under m g × 1 mm (the CoM off its linear prediction by less than a millimetre)
    EXPECT_LT(r->worst_residual, 1e-6) << "N or N·m";
    EXPECT_LT(r->worst_real_force_residual, 1e-6) << "N";
    EXPECT_LT(r->worst_real_moment_residual, m.totalMass() * 9.81 * 1e-3) << "N·m";
    std::printf("linearisation: worst moment residual %.4f N·m with the real CoM\n", r->worst_real_moment_residual);
  }
  const double hand_plain = -plain.last.forces.back().x(), hand_margin = -margin.last.forces.back().x();
  const double com_plain = comOf(plain.q).x(), com_margin = comOf(margin.q).x();
  std::printf("Fig. 3.18: CoM x %.4f → %.4f m (no margin) / %.4f m (±150 N margin); wall force %.1f / %.1f N; "
              "contact drift %.5f / %.5f m; right hand error %.4f / %.4f m; LCP %d, pivots %d\n",
              comOf(reach.q).x(), com_plain, com_margin, hand_plain, hand_margin, plain.worst_contact_drift,
              margin.worst_contact_drift, (framePosition(plain.q, "hand_r") - reach_r).norm(),
              (framePosition(margin.q, "hand_r") - reach_r).norm(), margin.last.lcp_size, margin.last.pivots);
  EXPECT_GT(com_margin, com_plain + 0.005) << "the margin leans the mannequin towards the wall";
  EXPECT_GT(hand_margin, hand_plain + 1.0) << "and it presses the wall harder";
}

// BalanceQp with bounds on y against the generic QP→LCP (Annex A) on a random problem: same optimum.
TEST(VariationalBalance, TheBoundedQpGivesTheGenericQpOptimum) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0, 1);
  const int mc = 3, ma = 4, nf = mc * ma, ny = 5, ne = 4, n = nf + ny;
  BalanceQp qp;
  qp.contacts = mc;
  qp.edges = ma;
  qp.B.resize(nf, ma);
  for (int i = 0; i < mc; ++i) {
    Eigen::MatrixXd R(ma, ma);
    for (int a = 0; a < ma; ++a)
      for (int b = 0; b < ma; ++b) R(a, b) = g(rng);
    qp.B.middleRows(i * ma, ma) = R.transpose() * R + Eigen::MatrixXd::Identity(ma, ma);
  }
  qp.f_pull.resize(nf);
  for (int k = 0; k < nf; ++k) qp.f_pull[k] = g(rng);
  qp.y_weight = Eigen::VectorXd::Constant(ny, 2.0);
  qp.y_desired.resize(ny);
  for (int k = 0; k < ny; ++k) qp.y_desired[k] = 3 * g(rng);
  qp.lower = Eigen::VectorXd::Constant(ny, -0.5);
  qp.upper = Eigen::VectorXd::Constant(ny, 0.5);
  qp.lower[1] = -std::numeric_limits<double>::infinity();
  qp.upper[2] = std::numeric_limits<double>::infinity();
  qp.C.resize(ne, n);
  for (int a = 0; a < ne; ++a)
    for (int b = 0; b < n; ++b) qp.C(a, b) = g(rng);
  qp.c.resize(ne);
  for (int a = 0; a < ne; ++a) qp.c[a] = g(rng);
  ASSERT_EQ(qp.solve(), QpOutcome::kSolved);
  // generic: min ½XᵀQ_A X − rᵀX = ½‖L X − L⁻ᵀr‖² + const with Q_A = LᵀL... as ½‖A X + b‖²_Q: A = I, Q = Q_A, b = −Q_A⁻¹r
  Eigen::MatrixXd QA = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < mc; ++i) QA.block(i * ma, i * ma, ma, ma) = qp.B.middleRows(i * ma, ma);
  QA.bottomRightCorner(ny, ny) = qp.y_weight.asDiagonal();
  Eigen::VectorXd rr(n);
  rr << qp.f_pull, qp.y_weight.cwiseProduct(qp.y_desired);
  lcp::QpProblem gen;
  gen.A = Eigen::MatrixXd::Identity(n, n);
  gen.Q = QA;
  gen.b = -QA.ldlt().solve(rr);
  gen.C = qp.C;
  gen.d = qp.c;
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> rhs;
  for (int k = 0; k < nf; ++k) {  // −f ≤ 0
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
    e[k] = -1;
    rows.push_back(e);
    rhs.push_back(0);
  }
  for (int j = 0; j < ny; ++j) {
    if (std::isfinite(qp.lower[j])) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
      e[nf + j] = -1;
      rows.push_back(e);
      rhs.push_back(-qp.lower[j]);
    }
    if (std::isfinite(qp.upper[j])) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
      e[nf + j] = 1;
      rows.push_back(e);
      rhs.push_back(qp.upper[j]);
    }
  }
  gen.E.resize(static_cast<Eigen::Index>(rows.size()), n);
  gen.f.resize(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    gen.E.row(static_cast<Eigen::Index>(k)) = rows[k].transpose();
    gen.f[static_cast<Eigen::Index>(k)] = rhs[k];
  }
  const lcp::QpResult res = lcp::solveQpAsLcp(gen);
  ASSERT_EQ(res.status, lcp::QpStatus::Solved) << res.message;
  EXPECT_LT((res.X - qp.X()).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LT((qp.C * qp.X() - qp.c).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GE(qp.X().head(nf).minCoeff(), -1e-12);
  for (int j = 0; j < ny; ++j) {
    EXPECT_GE(qp.X()[nf + j], qp.lower[j] - 1e-12) << j;
    EXPECT_LE(qp.X()[nf + j], qp.upper[j] + 1e-12) << j;
  }
  int at_bound = 0;  // the desired y (3σ) lies outside the ±0.5 box: some bounds are active
  for (int j = 0; j < ny; ++j) at_bound += std::abs(std::abs(qp.X()[nf + j]) - 0.5) < 1e-9;
  EXPECT_GT(at_bound, 0);
}

TEST(VariationalBalance, BadProblemsAreNamed) {
  const skeleton::Model& m = male50();
  const skeleton::VectorX q = skeleton::standingConfiguration(m);
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, q);
  VariationalBalanceSolver s(m);
  VariationalBalanceProblem p;
  p.contacts = soleContacts(m);
  p.held = holdCurrentPoses(p.contacts, d.oMi);
  ASSERT_EQ(s.solve(p, q).status, BalanceStatus::kSolved) << s.result().message;
  const auto expect = [&](const VariationalBalanceProblem& bad, const skeleton::VectorX& qq, const std::string& what) {
    const VariationalBalanceResult& r = s.solve(bad, qq);
    EXPECT_EQ(r.status, BalanceStatus::kInvalid);
    EXPECT_NE(r.message.find(what), std::string::npos) << "got: " << r.message;
  };
  expect(p, skeleton::VectorX::Zero(3), "q must have");
  VariationalBalanceProblem b = p;
  b.held.pop_back();
  expect(b, q, "is not held");
  b = p;
  b.contacts[2].joint = 999;
  expect(b, q, "contact 2: no joint 999");
  b = p;
  b.tasks = {{12345, {0, 0, 1}}};
  expect(b, q, "task 0: no frame");
  b = p;
  b.contacts[5].mu = -1;
  expect(b, q, "contact 5: mu");
  b = p;
  b.max_step = 0;
  expect(b, q, "max_step");
}

namespace {
/// Standing on both soles (4 points each), held where they are.
VariationalBalanceProblem standing(const skeleton::VectorX& q) {
  const skeleton::Model& m = male50();
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, q);
  VariationalBalanceProblem p;
  p.contacts = soleContacts(m);
  p.held = holdCurrentPoses(p.contacts, d.oMi);
  return p;
}

/// The static problem of the same contacts (world points at q) with the weight at `com` (fix_com: the
/// margins on G_f⁺, what forceMargin measures).
StaticBalanceProblem staticAt(const VariationalBalanceProblem& p, const skeleton::VectorX& q, const math::Vector3& com) {
  const skeleton::Model& m = male50();
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, q);
  StaticBalanceProblem s;
  for (const BodyContact& c : p.contacts)
    s.contacts.push_back({d.oMi[static_cast<std::size_t>(c.joint)].act(c.local_point), c.normal, c.mu, c.desired_force});
  s.mass = m.totalMass();
  s.gravity = p.gravity;
  s.edges = p.edges;
  s.fix_com = true;
  s.desired_com = com;
  return s;
}
}  // namespace

// Internal control (thesis 4.1): the criterion ‖δq − δq_d‖²_{w_q} instead of ‖δq‖²_{w_q}. With the same
// feasible set and the same other terms φ, the optima δq_1 (with δq_d) and δq_0 (without) satisfy
//   φ(δq_1) + ½w‖δq_1 − δq_d‖² ≤ φ(δq_0) + ½w‖δq_0 − δq_d‖²  and  φ(δq_0) + ½w‖δq_0‖² ≤ φ(δq_1) + ½w‖δq_1‖²,
// whose sum is (δq_1 − δq_0)·δq_d ≥ 0: the step moves towards δq_d. On the right elbow (free: no contact,
// no task; it only moves the CoM, by ~1 cm/rad, which the forces follow at ~10² N/rad, a curvature of
// ~10⁴ against w_q = 10⁶) the step is nearly all of δq_d.
TEST(VariationalBalance, DqDesiredPullsTheStepTowardsIt) {
  const skeleton::Model& m = male50();
  const skeleton::VectorX q = skeleton::standingConfiguration(m);
  const int elbow = testing_fixture::coordinate("elbow_r");
  VariationalBalanceSolver solver(m);
  VariationalBalanceProblem p = standing(q);
  ASSERT_EQ(solver.solve(p, q).status, BalanceStatus::kSolved) << solver.result().message;
  const skeleton::VectorX dq0 = solver.result().dq;
  const double d = 0.01;  // rad, inside max_step and the elbow's range (0–150°) from q
  ASSERT_LE(q[elbow] + d, m.upper_limit[elbow]);
  ASSERT_GE(q[elbow] + d, m.lower_limit[elbow]);
  p.dq_desired = skeleton::VectorX::Zero(m.nv);
  p.dq_desired[elbow] = d;
  ASSERT_EQ(solver.solve(p, q).status, BalanceStatus::kSolved) << solver.result().message;
  const skeleton::VectorX dq1 = solver.result().dq;
  std::printf("dq_desired %.4f on elbow_r: step %.6f without, %.6f with\n", d, dq0[elbow], dq1[elbow]);
  EXPECT_GE((dq1 - dq0).dot(p.dq_desired), -1e-12);
  EXPECT_LT(std::abs(dq1[elbow] - d), std::abs(dq0[elbow] - d));
  EXPECT_GT(dq1[elbow] - dq0[elbow], 0.9 * d);
  EXPECT_LT(solver.result().equilibrium_residual, 1e-6);
  // a zero δq_d is the thesis's (3.107): the same step as none
  p.dq_desired.setZero();
  ASSERT_EQ(solver.solve(p, q).status, BalanceStatus::kSolved);
  EXPECT_LT((solver.result().dq - dq0).cwiseAbs().maxCoeff(), 1e-12);

  // bad sizes and values: kInvalid naming dq_desired, no throw
  for (int size : {m.nv - 1, m.nv + 6, 1}) {
    p.dq_desired = skeleton::VectorX::Zero(size);
    VariationalBalanceResult r;
    EXPECT_NO_THROW(r = solver.solve(p, q)) << size;
    EXPECT_EQ(r.status, BalanceStatus::kInvalid) << size;
    EXPECT_NE(r.message.find("dq_desired"), std::string::npos) << r.message;
  }
  p.dq_desired = skeleton::VectorX::Zero(m.nv);
  p.dq_desired[elbow] = std::nan("");
  EXPECT_EQ(solver.solve(p, q).status, BalanceStatus::kInvalid);
  EXPECT_NE(solver.result().message.find("dq_desired"), std::string::npos) << solver.result().message;
}

// margins_at_com: the edge reserves come from G_f⁺ (the CoM given), so every push D_i is balanced by
// non-negative edge forces at the step's own linearised CoM: the static problem of the same contacts with
// the weight at result.com (fix_com, the margins on G_f⁺ as forceMargin takes them) is solvable with those
// pushes, and forceMargin there is at least the push asked for. Two cases: (a) a forward push of 95 % of
// the standing posture's margin, no task; (b) fore-aft pushes of 90 % of it while the right hand reaches
// forwards and down (the CoM moves ~7 cm). The thesis form (margins_at_com off) is run alongside and its
// margin at its own linearised CoM printed: in (a) it is below the push asked for (the part of the push's
// moment its G⁺ gives to a CoM shift the step does not make), which is what this option is for.
TEST(VariationalBalance, MarginsAtComHoldEachPushAtTheLinearisedCom) {
  const skeleton::Model& m = male50();
  const skeleton::VectorX q0 = skeleton::standingConfiguration(m);
  const math::Vector3 at = comOf(q0);
  const double tol = 0.25;  // N, forceMargin's bisection
  struct Case {
    const char* name;
    std::vector<math::Vector3> dirs;
    double fraction;
    bool reach;
    int steps;
  };
  for (const Case& c : {Case{"forward push, standing", {math::Vector3::UnitX()}, 0.95, false, 5},
                        Case{"fore-aft pushes, reaching", {math::Vector3::UnitX(), -math::Vector3::UnitX()}, 0.9, true, 40}}) {
    SCOPED_TRACE(c.name);
    skeleton::VectorX q = q0;
    VariationalBalanceProblem p = standing(q);
    StaticBalanceSolver stat;
    const ForceMarginResult m0 = forceMargin(stat, staticAt(p, q, at), c.dirs, at, 2000.0, tol);
    ASSERT_EQ(m0.status, BalanceStatus::kSolved) << m0.message;
    ASSERT_GT(m0.margin_n, 10.0);
    const double F = c.fraction * m0.margin_n;
    for (const math::Vector3& d : c.dirs) {
      math::Vector6 D;
      D << at.cross(F * d), F * d;
      p.force_margins.push_back(D);
    }
    p.margins_at_com = true;
    const math::Vector3 reach = framePosition(q, "hand_r") + math::Vector3(0.25, -0.05, 0.10);
    if (c.reach) p.tasks = {{m.frameIndex("hand_r"), reach}};
    VariationalBalanceSolver solver(m), thesis(m);
    double worst = 2000.0, worst_thesis = 2000.0;
    for (int step = 0; step < c.steps; ++step) {
      const VariationalBalanceResult& r = solver.solve(p, q);
      ASSERT_EQ(r.status, BalanceStatus::kSolved) << "step " << step << ": " << r.message;
      StaticBalanceProblem s = staticAt(p, q, r.com);
      s.force_margins = p.force_margins;
      EXPECT_EQ(stat.solve(s).status, BalanceStatus::kSolved) << "step " << step << ": " << stat.result().message;
      const double fm = forceMargin(stat, staticAt(p, q, r.com), c.dirs, at, 2000.0, tol).margin_n;
      EXPECT_GE(fm, F - tol) << "step " << step;
      worst = std::min(worst, fm);
      VariationalBalanceProblem t = p;
      t.margins_at_com = false;
      const VariationalBalanceResult& rt = thesis.solve(t, q);
      if (rt.status == BalanceStatus::kSolved)
        worst_thesis = std::min(worst_thesis, forceMargin(stat, staticAt(p, q, rt.com), c.dirs, at, 2000.0, tol).margin_n);
      q = skeleton::integrate(m, q, r.dq);
    }
    std::printf("%s: push %.1f N (standing margin %.1f N); CoM x %.4f -> %.4f m; margin at the linearised CoM down to "
                "%.1f N (margins_at_com), %.1f N (thesis form)\n",
                c.name, F, m0.margin_n, at.x(), comOf(q).x(), worst, worst_thesis);
    if (c.reach) {
      EXPECT_LT((framePosition(q, "hand_r") - reach).norm(), 0.01) << "the hand reaches";
      EXPECT_GT(comOf(q).x() - at.x(), 0.02) << "and the CoM moves with it";
    }

    // com_margins with margins_at_com: kInvalid, named
    p.com_margins = {math::Vector3(0.01, 0, 0)};
    EXPECT_EQ(solver.solve(p, q).status, BalanceStatus::kInvalid);
    EXPECT_NE(solver.result().message.find("com_margins"), std::string::npos) << solver.result().message;
    p.margins_at_com = false;
    EXPECT_EQ(solver.solve(p, q).status, BalanceStatus::kSolved) << solver.result().message;
  }
}
