#include <gtest/gtest.h>

#include <random>

#include "mannequin/lcp/qp.hpp"
#include "mannequin/lcp/testing.hpp"

using namespace mannequin::lcp;

namespace {

QpProblem randomQp(Index m, Index ne, Index ni, std::uint32_t seed) {
  std::mt19937 rng(seed);
  QpProblem qp;
  qp.A = gen::uniform(m + 2, m, -1, 1, rng);
  qp.b = gen::uniform(m + 2, 1, -1, 1, rng);
  const Eigen::MatrixXd B = gen::uniform(m + 2, m + 2, -1, 1, rng);
  qp.Q = B * B.transpose() + Eigen::MatrixXd::Identity(m + 2, m + 2);
  qp.C = gen::uniform(ne, m, -1, 1, rng);
  qp.d = gen::uniform(ne, 1, -1, 1, rng);
  qp.E = gen::uniform(ni, m, -1, 1, rng);
  qp.f = gen::uniform(ni, 1, -0.2, 1, rng);
  return qp;
}

}  // namespace

// KKT of (3)-(5): stationarity, primal and dual feasibility, complementarity
TEST(QpAsLcp, KktHolds) {
  for (std::uint32_t seed = 1; seed <= 8; ++seed) {
    const auto qp = randomQp(6, 2, 8, seed);
    const auto r = solveQpAsLcp(qp);
    ASSERT_EQ(r.status, QpStatus::Solved) << r.message;
    const Eigen::VectorXd grad = qp.A.transpose() * qp.Q * (qp.A * r.X + qp.b) +
                                 qp.C.transpose() * r.lambda + qp.E.transpose() * r.mu;
    EXPECT_LE(grad.lpNorm<Eigen::Infinity>(), 1e-9);
    EXPECT_LE((qp.C * r.X - qp.d).lpNorm<Eigen::Infinity>(), 1e-9);
    const Eigen::VectorXd slack = qp.f - qp.E * r.X;
    EXPECT_GE(slack.minCoeff(), -1e-9);
    EXPECT_GE(r.mu.minCoeff(), 0.0);
    EXPECT_LE(std::abs(slack.dot(r.mu)), 1e-9);
  }
}

// 1-D check by hand: min ½(x − 2)² s.t. x ≤ 1 → x = 1, μ = 1
TEST(QpAsLcp, HandChecked) {
  QpProblem qp;
  qp.A = Eigen::MatrixXd::Identity(1, 1);
  qp.b = Eigen::VectorXd::Constant(1, -2.0);
  qp.Q = Eigen::MatrixXd::Identity(1, 1);
  qp.C.resize(0, 1);
  qp.d.resize(0);
  qp.E = Eigen::MatrixXd::Identity(1, 1);
  qp.f = Eigen::VectorXd::Constant(1, 1.0);
  const auto r = solveQpAsLcp(qp);
  ASSERT_EQ(r.status, QpStatus::Solved);
  EXPECT_NEAR(r.X[0], 1.0, 1e-12);
  EXPECT_NEAR(r.mu[0], 1.0, 1e-12);
}

TEST(QpAsLcp, RejectsBadEqualities) {
  auto qp = randomQp(3, 4, 2, 1);  // 4 equality rows, 3 unknowns
  EXPECT_EQ(solveQpAsLcp(qp).status, QpStatus::OverConstrained);
  qp = randomQp(4, 2, 2, 2);
  qp.C.row(1) = 2.0 * qp.C.row(0);
  EXPECT_EQ(solveQpAsLcp(qp).status, QpStatus::RankDeficient);
  qp = randomQp(4, 1, 2, 3);
  qp.A.col(3) = qp.A.col(2);  // ker A ≠ {0}
  EXPECT_EQ(solveQpAsLcp(qp).status, QpStatus::NotConvex);
  qp = randomQp(4, 1, 2, 3);
  qp.b.resize(1);
  EXPECT_EQ(solveQpAsLcp(qp).status, QpStatus::Invalid);
}

// x ≤ 0 and −x ≤ −1 cannot both hold: ray termination → infeasible
TEST(QpAsLcp, Infeasible) {
  QpProblem qp;
  qp.A = Eigen::MatrixXd::Identity(1, 1);
  qp.b = Eigen::VectorXd::Zero(1);
  qp.Q = Eigen::MatrixXd::Identity(1, 1);
  qp.C.resize(0, 1);
  qp.d.resize(0);
  qp.E.resize(2, 1);
  qp.E << 1.0, -1.0;
  qp.f = Eigen::Vector2d(0.0, -1.0);
  EXPECT_EQ(solveQpAsLcp(qp).status, QpStatus::Infeasible);
}
