// Static balance with non-coplanar frictional contacts (thesis 3.3.2.2): the equilibrium matrix, the
// criterion solved as an LCP against the generic QP→LCP path, the margins' SVD form, infeasible and
// invalid requests, and the thesis's figures 3.12–3.17 on a standing 75 kg mannequin with a hand on a
// wall in front of it.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "mannequin/balance/static_balance.hpp"
#include "mannequin/lcp/qp.hpp"
#include "mannequin/math/so3.hpp"

using namespace mannequin;
using namespace mannequin::balance;

namespace {

constexpr double kMass = 75.0, kG = 9.81;
// feet: heel x = −0.05, toes x = 0.20; left y ∈ [0.06, 0.15], right y ∈ [−0.15, −0.06]
constexpr double kHeel = -0.05, kToe = 0.20;
// the wall: the plane x = 0.6, the right hand on it at 1.3 m
constexpr double kWall = 0.6;

StaticBalanceProblem standing(bool hand_on_wall) {
  StaticBalanceProblem p;
  p.mass = kMass;
  for (double y0 : {0.06, -0.15})
    for (double x : {kHeel, kToe})
      for (double y : {y0, y0 + 0.09}) p.contacts.push_back({{x, y, 0}, {0, 0, 1}, 0.6, {0, 0, 0}});
  if (hand_on_wall) p.contacts.push_back({{kWall, -0.2, 1.3}, {-1, 0, 0}, 0.6, {0, 0, 0}});
  p.desired_com = {0.075, 0, 0.95};  // between the feet
  p.alpha = 1.0;                      // small tangential forces (3.69)
  return p;
}

const math::Vector3& handForce(const StaticBalanceResult& r) { return r.forces.back(); }
double handNormal(const StaticBalanceResult& r) { return -handForce(r).x(); }

}  // namespace

// G X is the net wrench (moment about the origin, force) of the edge forces and the weight at x_com,
// computed here from the contact forces directly: Σ p_i × f_i + x × m g, Σ f_i + m g (3.39–3.52).
TEST(StaticBalance, EquilibriumMatrixIsTheNetWrenchOfContactsAndWeight) {
  StaticBalanceProblem p = standing(true);
  p.gravity = {0.3, -0.2, -9.7};  // any direction: the CoM columns are −[m g]×
  StaticBalanceSolver s;
  ASSERT_EQ(s.solve(p).status, BalanceStatus::kSolved) << s.result().message;
  const Eigen::MatrixXd& G = s.equilibriumMatrix();
  const Eigen::MatrixXd& A = s.edgeDirections();
  const int ma = p.edges, nf = static_cast<int>(p.contacts.size()) * ma;
  ASSERT_EQ(G.rows(), 6);
  ASSERT_EQ(G.cols(), nf + 3);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 50);
  Eigen::VectorXd X(nf + 3);
  for (int j = 0; j < nf; ++j) X[j] = u(rng);
  X.tail<3>() = math::Vector3(0.1, -0.05, 0.9);
  math::Vector3 moment = X.tail<3>().cross(p.mass * p.gravity), force = p.mass * p.gravity;
  for (std::size_t i = 0; i < p.contacts.size(); ++i) {
    const math::Vector3 f = A.middleCols(static_cast<Eigen::Index>(i) * ma, ma) * X.segment(static_cast<Eigen::Index>(i) * ma, ma);
    moment += p.contacts[i].point.cross(f);
    force += f;
  }
  // G X = W ⇔ net wrench = −W_ext: G X − (the weight's constant part) is the net wrench
  Eigen::Matrix<double, 6, 1> net;
  net << moment, force;
  Eigen::Matrix<double, 6, 1> GX = G * X;
  GX.tail<3>() += p.mass * p.gravity;
  EXPECT_LT((GX - net).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((s.equilibriumRhs().tail<3>() + p.mass * p.gravity).norm(), 1e-12);
  // unit edges at atan(μ) from their contact's normal (3.56)
  for (int j = 0; j < nf; ++j) {
    const math::Vector3 n = p.contacts[static_cast<std::size_t>(j / ma)].normal.normalized();
    EXPECT_NEAR(A.col(j).norm(), 1.0, 1e-12);
    EXPECT_NEAR(std::acos(A.col(j).dot(n)), std::atan(0.6), 1e-12);
  }
}

// The structured solve (block-diagonal Q_A⁻¹, rank-6 term) gives the generic QP→LCP path's optimum
// (Annex A: min ½‖A'X + b‖²_Q, A' = [I; (I − NNᵀ)A], b = [−X_d; 0], s.t. GX = W, −I_f X ≤ 0).
TEST(StaticBalance, TheStructuredLcpGivesTheGenericQpOptimum) {
  for (double xd : {0.075, 0.3, 0.5}) {
    StaticBalanceProblem p = standing(true);
    p.desired_com.x() = xd;
    p.contacts.back().desired_force = {-30, 0, 5};  // push the wall a bit
    StaticBalanceSolver s;
    const StaticBalanceResult& r = s.solve(p);
    ASSERT_EQ(r.status, BalanceStatus::kSolved) << r.message;
    const int ma = p.edges, mc = static_cast<int>(p.contacts.size()), nf = mc * ma, n = nf + 3;
    const Eigen::MatrixXd& A = s.edgeDirections();
    lcp::QpProblem qp;
    qp.A.setZero(n + 3 * mc, n);
    qp.A.topRows(n).setIdentity();
    for (int i = 0; i < mc; ++i) {
      const math::Vector3 nn = p.contacts[static_cast<std::size_t>(i)].normal.normalized();
      qp.A.block(n + 3 * i, i * ma, 3, ma) = (math::Matrix3::Identity() - nn * nn.transpose()) * A.middleCols(i * ma, ma);
    }
    Eigen::VectorXd Xd(n);
    for (int i = 0; i < mc; ++i) {
      const Eigen::MatrixXd Ai = A.middleCols(i * ma, ma);
      Xd.segment(i * ma, ma) = Ai.completeOrthogonalDecomposition().solve(p.contacts[static_cast<std::size_t>(i)].desired_force);
    }
    Xd.tail<3>() = p.desired_com;
    qp.b = Eigen::VectorXd::Zero(n + 3 * mc);
    qp.b.head(n) = -Xd;
    qp.Q = Eigen::MatrixXd::Zero(n + 3 * mc, n + 3 * mc);
    qp.Q.diagonal().head(nf).setConstant(p.force_weight);
    qp.Q.diagonal().segment(nf, 3).setConstant(p.com_weight);
    qp.Q.diagonal().tail(3 * mc).setConstant(p.alpha);
    qp.C = s.equilibriumMatrix();
    qp.d = s.equilibriumRhs();
    qp.E = Eigen::MatrixXd::Zero(nf, n);
    qp.E.leftCols(nf) = -Eigen::MatrixXd::Identity(nf, nf);
    qp.f = Eigen::VectorXd::Zero(nf);
    const lcp::QpResult g = lcp::solveQpAsLcp(qp);
    ASSERT_EQ(g.status, lcp::QpStatus::Solved) << g.message;
    EXPECT_LT((g.X.head(nf) - r.edge_forces).cwiseAbs().maxCoeff(), 1e-6) << "x_d " << xd;
    EXPECT_LT((g.X.tail<3>() - r.com).cwiseAbs().maxCoeff(), 1e-9) << "x_d " << xd;
    EXPECT_LT(r.equilibrium_residual, 1e-8);
  }
}

// Fig. 3.12: the desired CoM between the feet and no desired hand force: the hand on the wall carries
// (almost) nothing and the CoM is where it was desired — what a real person standing would do.
TEST(StaticBalance, Fig3_12_CoMBetweenTheFeetTheHandCarriesNothing) {
  const StaticBalanceResult r = solveStaticBalance(standing(true));
  ASSERT_EQ(r.status, BalanceStatus::kSolved) << r.message;
  std::printf("Fig. 3.12: hand force %.3f N, CoM (%.4f, %.4f) m\n", handForce(r).norm(), r.com.x(), r.com.y());
  EXPECT_LT(handForce(r).norm(), 0.01 * kMass * kG);  // under 1 % of the weight
  EXPECT_LT((r.com - math::Vector3(0.075, 0, 0.95)).head<2>().norm(), 1e-3);
  EXPECT_LT(r.equilibrium_residual, 1e-8);
  // the feet carry the weight
  double up = 0;
  for (std::size_t i = 0; i + 1 < r.forces.size(); ++i) up += r.forces[i].z();
  EXPECT_NEAR(up, kMass * kG, 0.01 * kMass * kG);
}

// Fig. 3.13–3.14: the desired CoM moved towards the wall, past the toes: the mannequin leans on the wall
// and the hand force grows as the desired CoM nears the wall.
TEST(StaticBalance, Fig3_13_14_TheHandForceGrowsAsTheDesiredCoMNearsTheWall) {
  double previous = -1;
  std::printf("Fig. 3.14: desired CoM x, CoM x, hand normal force\n");
  for (double xd = 0.075; xd <= 0.55 + 1e-9; xd += 0.025) {
    StaticBalanceProblem p = standing(true);
    p.desired_com.x() = xd;
    const StaticBalanceResult r = solveStaticBalance(p);
    ASSERT_EQ(r.status, BalanceStatus::kSolved) << r.message;
    const double f = handNormal(r);
    std::printf("  %.3f  %.4f  %8.2f N\n", xd, r.com.x(), f);
    EXPECT_GE(f, previous - 1e-6) << "x_d " << xd;  // monotonic (Fig. 3.14)
    previous = f;
    EXPECT_GE(f, -1e-9);  // a wall only pushes
    if (r.com.x() > kToe + 0.01) {
      // past the toes only the hand holds the CoM up: about the toe line, the weight's moment
      // m g (x − x_toe) and the heels' (which add to it) are balanced by the hand's alone,
      // 1.3 f_n + (x_wall − x_toe) f_z = m g (x − x_toe) + 0.25 f_heels ≥ m g (x − x_toe)
      EXPECT_GT(f, 0.0);
      const double moment = kMass * kG * (r.com.x() - kToe);
      EXPECT_GE(f * 1.3 + handForce(r).z() * (kWall - kToe), moment - 1e-6 * (1 + moment));
    }
  }
  EXPECT_GT(previous, 0.1 * kMass * kG) << "leaning far towards the wall, the hand carries a real share";
}

// With the CoM free and no hand, the optimum puts the CoM over the feet even when the desired CoM is
// outside them (statics: the weight's line of action through the support polygon).
TEST(StaticBalance, WithoutTheHandTheCoMStaysOverTheFeet) {
  StaticBalanceProblem p = standing(false);
  p.desired_com = {0.5, 0.3, 0.95};
  const StaticBalanceResult r = solveStaticBalance(p);
  ASSERT_EQ(r.status, BalanceStatus::kSolved) << r.message;
  EXPECT_GE(r.com.x(), kHeel - 1e-9);
  EXPECT_LE(r.com.x(), kToe + 1e-9);
  EXPECT_LE(r.com.y(), 0.15 + 1e-9);
  EXPECT_GT(r.com.x(), kToe - 0.02) << "as near the desired CoM as the feet allow";
  EXPECT_GE(r.min_raw_edge_force, -1e-9);  // the LCP's own answer, before rounding
}

// The CoM-position margin computed as Π_fx Π_xx⁺ Δx is the thesis's SVD form Π_f T (Δx; 0) (3.76–3.83),
// T = V Σ_ext⁻¹ U_extᵀ built here from Π = I − G⁺G.
TEST(StaticBalance, TheCoMMarginIsTheSvdChangeOfVariables) {
  StaticBalanceProblem p = standing(true);
  const math::Vector3 dx(0.08, -0.03, 0.0);
  p.com_margins = {dx};
  StaticBalanceSolver s;
  const StaticBalanceResult& r = s.solve(p);
  ASSERT_EQ(r.status, BalanceStatus::kSolved) << r.message;
  const Eigen::MatrixXd& G = s.equilibriumMatrix();
  const Eigen::Index n = G.cols(), nf = n - 3;
  const Eigen::MatrixXd Gp = G.completeOrthogonalDecomposition().pseudoInverse();
  const Eigen::MatrixXd Pi = Eigen::MatrixXd::Identity(n, n) - Gp * G;
  const Eigen::VectorXd nu = Gp * s.equilibriumRhs();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Pi.bottomRows(3), Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sr = svd.singularValues();
  ASSERT_GT(sr.minCoeff(), 1e-6);  // the CoM can move in every direction within ker G here
  Eigen::MatrixXd Sext = Eigen::MatrixXd::Identity(n, n), Uext = Eigen::MatrixXd::Identity(n, n);
  Sext.topLeftCorner(3, 3) = sr.asDiagonal();
  Uext.topLeftCorner(3, 3) = svd.matrixU();
  const Eigen::MatrixXd T = svd.matrixV() * Sext.inverse() * Uext.transpose();
  EXPECT_LT((Pi.bottomRows(3) * T - Eigen::MatrixXd::Identity(3, n)).cwiseAbs().maxCoeff(), 1e-9);  // (3.81)
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
  e.head<3>() = dx;
  const Eigen::VectorXd nu_i = Pi.topRows(nf) * T * e + nu.head(nf);  // (3.83)
  const Eigen::VectorXd nu_prime = nu_i.cwiseMin(nu.head(nf));        // (3.86), with the initial polytope
  EXPECT_LT((r.margin_reserve - (nu.head(nf) - nu_prime)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT(r.margin_reserve.maxCoeff(), 1e-3) << "the margin moves some facets in";
  // (3.92): the final X is in equilibrium and every edge keeps its reserve
  EXPECT_LT(r.equilibrium_residual, 1e-8);
  EXPECT_TRUE((r.edge_forces.array() >= r.margin_reserve.array() - 1e-9).all());
}

// Fig. 3.16: with a CoM-position margin the CoM moves towards the wall and a hand force appears.
// Fig. 3.17: a disturbing-force margin leans the mannequin on the wall too, the more so the larger the
// force. The thesis's figure also finds the force margin's effect "more marked" than 3.16b's, at values it
// does not give; at the same moment about the feet (a push F at the CoM's height with F·0.95 m = m g d)
// ours is the milder of the two (printed below; docs/balance.md), so that comparison is not asserted.
TEST(StaticBalance, Fig3_16_17_MarginsLeanTheMannequinOnTheWall) {
  const StaticBalanceResult none = solveStaticBalance(standing(true));
  ASSERT_EQ(none.status, BalanceStatus::kSolved) << none.message;
  StaticBalanceProblem pos = standing(true);
  const double d = 0.15;  // the CoM may be pushed 15 cm forwards or backwards
  pos.com_margins = {{d, 0, 0}, {-d, 0, 0}};
  const StaticBalanceResult rp = solveStaticBalance(pos);
  ASSERT_EQ(rp.status, BalanceStatus::kSolved) << rp.message;
  EXPECT_GT(rp.com.x(), none.com.x() + 1e-3);
  EXPECT_GT(handNormal(rp), handNormal(none) + 1.0);
  EXPECT_LT(rp.equilibrium_residual, 1e-8);
  // horizontal pushes forwards and backwards at the CoM's height, of growing size
  double previous_com = none.com.x(), previous_hand = handNormal(none);
  for (double scale : {1.0, 2.0, 3.0}) {
    const double F = scale * kMass * kG * d / 0.95;
    StaticBalanceProblem frc = standing(true);
    for (double sgn : {1.0, -1.0}) {
      const math::Vector3 force(sgn * F, 0, 0), at(0.075, 0, 0.95);
      math::Vector6 D;
      D << at.cross(force), force;
      frc.force_margins.push_back(D);
    }
    const StaticBalanceResult rf = solveStaticBalance(frc);
    ASSERT_EQ(rf.status, BalanceStatus::kSolved) << rf.message;
    std::printf("Fig. 3.16/3.17: CoM x %.4f / %.4f / %.4f m, hand normal force %.2f / %.2f / %.2f N "
                "(none / position margin %.2f m / force margin %.0f N)\n",
                none.com.x(), rp.com.x(), rf.com.x(), handNormal(none), handNormal(rp), handNormal(rf), d, F);
    EXPECT_GT(rf.com.x(), previous_com) << F << " N";
    EXPECT_GT(handNormal(rf), previous_hand + 1.0) << F << " N";
    EXPECT_LT(rf.equilibrium_residual, 1e-8);
    previous_com = rf.com.x();
    previous_hand = handNormal(rf);
  }
}

// No equilibrium exists: reported as such (Lemke's ray on a PSD M), never as a solved state.
TEST(StaticBalance, InfeasibleRequestsAreReportedAsSuch) {
  // hands pressed on a ceiling: the contacts can only push down
  StaticBalanceProblem p;
  p.mass = kMass;
  for (double x : {0.0, 0.3})
    for (double y : {-0.2, 0.2}) p.contacts.push_back({{x, y, 2.0}, {0, 0, -1}, 0.5, {0, 0, 0}});
  StaticBalanceResult r = solveStaticBalance(p);
  EXPECT_EQ(r.status, BalanceStatus::kInfeasible) << r.message;
  EXPECT_NE(r.message.find("no equilibrium"), std::string::npos) << r.message;
  // standing, but a margin larger than any the feet and the hand can hold: a 2000 N push sideways
  StaticBalanceProblem q = standing(true);
  math::Vector6 D;
  const math::Vector3 force(0, 2000, 0), at(0.075, 0, 0.95);
  D << at.cross(force), force;
  q.force_margins = {D};
  r = solveStaticBalance(q);
  EXPECT_EQ(r.status, BalanceStatus::kInfeasible) << r.message;
  EXPECT_NE(r.message.find("margins"), std::string::npos) << r.message;
  // a frictionless wall alone cannot make a vertical force: G is rank deficient
  StaticBalanceProblem w;
  w.mass = kMass;
  w.contacts.push_back({{0.6, 0, 1.3}, {-1, 0, 0}, 0.0, {0, 0, 0}});
  w.contacts.push_back({{0.6, 0.3, 1.3}, {-1, 0, 0}, 0.0, {0, 0, 0}});
  r = solveStaticBalance(w);
  EXPECT_EQ(r.status, BalanceStatus::kDegenerate) << r.message;
}

// A given posture (fix_com): the CoM fixed, only the forces unknown. Fore-aft pushes F at the CoM's height
// h = 0.95 m: statics says the feet alone hold F up to min(m g (x_toe − x)/h, m g (x − x_heel)/h) (tipping)
// and μ m g (sliding). The solver's equilibrium is exact (a push 3 % past the bound has no equilibrium,
// 3 % below has one), and the margin of (3.93–3.95), conservative, stays below the bound, is held for
// real, and grows as the CoM nears the middle of the feet.
TEST(StaticBalance, TheForceMarginOfAGivenPostureIsBelowTheTippingBound) {
  const double h = 0.95, mg = kMass * kG;
  const std::vector<math::Vector3> fore_aft = {{1, 0, 0}, {-1, 0, 0}};
  double previous = -1;
  for (double xc : {-0.03, 0.0, 0.03, 0.075}) {
    StaticBalanceProblem p = standing(false);
    p.fix_com = true;
    p.desired_com = {xc, 0, h};
    const double bound = std::min({mg * (kToe - xc) / h, mg * (xc - kHeel) / h, 0.6 * mg});
    const auto push = [&](double F) {
      StaticBalanceProblem q = p;
      const math::Vector3 f(F, 0, 0);
      q.external_wrench << p.desired_com.cross(f), f;
      return solveStaticBalance(q).status;
    };
    const double tip_fwd = mg * (kToe - xc) / h, tip_back = mg * (xc - kHeel) / h;
    EXPECT_EQ(push(0.97 * tip_fwd), BalanceStatus::kSolved) << xc;
    EXPECT_EQ(push(1.03 * tip_fwd), BalanceStatus::kInfeasible) << xc;
    EXPECT_EQ(push(-0.97 * tip_back), BalanceStatus::kSolved) << xc;
    EXPECT_EQ(push(-1.03 * tip_back), BalanceStatus::kInfeasible) << xc;
    StaticBalanceSolver s;
    const ForceMarginResult m = forceMargin(s, p, fore_aft, p.desired_com, 2000.0, 0.5);
    ASSERT_EQ(m.status, BalanceStatus::kSolved) << m.message;
    std::printf("CoM x %.3f: force margin %.1f N, tipping/sliding bound %.1f N (%d solves)\n", xc, m.margin_n, bound, m.solves);
    EXPECT_GT(m.margin_n, 0.0);
    EXPECT_LE(m.margin_n, bound + 0.5);
    EXPECT_EQ(push(m.margin_n), BalanceStatus::kSolved);
    EXPECT_EQ(push(-m.margin_n), BalanceStatus::kSolved);
    EXPECT_GE(m.margin_n, previous) << "the margin grows as the CoM nears the middle of the feet";
    previous = m.margin_n;
  }
  // the hand on the wall in front holds forward pushes too
  StaticBalanceProblem p = standing(true);
  p.fix_com = true;
  p.desired_com = {0.15, 0, h};
  StaticBalanceSolver s;
  const double with_hand = forceMargin(s, p, {{1, 0, 0}}, p.desired_com).margin_n;
  p = standing(false);
  p.fix_com = true;
  p.desired_com = {0.15, 0, h};
  const double feet_only = forceMargin(s, p, {{1, 0, 0}}, p.desired_com).margin_n;
  std::printf("forward push margin at CoM x 0.15: %.1f N with the hand on the wall, %.1f N on the feet alone\n", with_hand, feet_only);
  EXPECT_GT(with_hand, feet_only + 10.0);
  // a posture that is not balanced has no margin, and says so
  p.desired_com = {0.5, 0, h};
  const ForceMarginResult off = forceMargin(s, p, fore_aft, p.desired_com);
  EXPECT_EQ(off.status, BalanceStatus::kInfeasible);
  EXPECT_EQ(off.margin_n, 0.0);
  p.com_margins = {{0.1, 0, 0}};
  EXPECT_EQ(solveStaticBalance(p).status, BalanceStatus::kInvalid);
}

TEST(StaticBalance, BadInputIsNamed) {
  const auto expect = [](const StaticBalanceProblem& p, const std::string& what) {
    const StaticBalanceResult r = solveStaticBalance(p);
    EXPECT_EQ(r.status, BalanceStatus::kInvalid);
    EXPECT_NE(r.message.find(what), std::string::npos) << "got: " << r.message;
  };
  StaticBalanceProblem p = standing(true);
  p.mass = -1;
  expect(p, "mass");
  p = standing(true);
  p.contacts[3].normal = {0, 0, 0};
  expect(p, "contact 3: normal");
  p = standing(true);
  p.contacts[8].mu = std::nan("");
  expect(p, "contact 8: mu");
  p = standing(true);
  p.edges = 2;
  expect(p, "edges");
  p = standing(true);
  p.contacts.clear();
  expect(p, "no contact");
  p = standing(true);
  p.com_margins = {{0, std::numeric_limits<double>::infinity(), 0}};
  expect(p, "com_margins[0]");
  p = standing(true);
  p.desired_com.x() = std::nan("");
  expect(p, "desired_com");
}
