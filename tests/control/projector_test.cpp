// b_a-weighted projectors (2.74–2.76) by pivoted LDLᵀ vs SVD, and the augmented impedance with
// K = b_a (2.29–2.42).
#include <gtest/gtest.h>

#include <random>

#include "common.hpp"
#include "mannequin/math/pinv.hpp"

using namespace mannequin;
using namespace mannequin::control;
using namespace mannequin::control::testing;

namespace {
MatrixX randomMatrix(int m, int n, std::mt19937& rng) {
  std::normal_distribution<double> g;
  MatrixX A(m, n);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = g(rng);
  return A;
}

void expectSameProjector(const MatrixX& J, const VectorX& w, int expected_rank) {
  const VectorX w_inv = w.cwiseInverse();
  WeightedNullSpace ldlt(J.rows(), J.cols(), ProjectorMethod::kLdlt, 1e-9);
  WeightedNullSpace svd(J.rows(), J.cols(), ProjectorMethod::kSvd, 1e-9);
  ldlt.compute(J, w_inv);
  svd.compute(J, w_inv);
  EXPECT_EQ(ldlt.rank(), expected_rank);
  EXPECT_EQ(svd.rank(), expected_rank);
  const MatrixX P1 = ldlt.matrix(), P2 = svd.matrix();
  const MatrixX P3 = math::weightedNullSpaceProjector(J, MatrixX(w.asDiagonal()), 1e-9);
  const double scale = 1.0 + P2.norm();
  EXPECT_LT((P1 - P2).norm() / scale, 1e-8);
  EXPECT_LT((P1 - P3).norm() / scale, 1e-8);
  // J Π = 0, Π² = Π, J W⁻¹ Πᵀ = 0 (2.75–2.76)
  EXPECT_LT((J * P1).norm() / (1 + J.norm()), 1e-8);
  EXPECT_LT((P1 * P1 - P1).norm() / scale, 1e-8);
  EXPECT_LT((J * w_inv.asDiagonal() * P1.transpose()).norm() / (1 + J.norm()), 1e-8);
}

/// Π of PriorityGramFactor for the first m rows, dense (columns of Πᵀ are Πᵀ e_k).
MatrixX priorityProjector(PriorityGramFactor& f, const MatrixX& J, const VectorX& w_inv, int m) {
  MatrixX PiT(J.cols(), J.cols());
  VectorX e(J.cols()), col(J.cols());
  for (int k = 0; k < J.cols(); ++k) {
    e.setZero();
    e(k) = 1.0;
    f.projectTorque(J, w_inv, m, e, col);
    PiT.col(k) = col;
  }
  return PiT.transpose();
}

/// One unpivoted factorisation of J's Gram gives, for every prefix of rows, the projector and rank of
/// the reference SVD projector of those rows alone.
void expectPrefixProjectors(const MatrixX& J, const VectorX& w, double svd_tolerance) {
  const VectorX w_inv = w.cwiseInverse();
  const int rows = static_cast<int>(J.rows()), n = static_cast<int>(J.cols());
  PriorityGramFactor f(rows, n, 1e-9);
  const MatrixX G = J * w_inv.asDiagonal() * J.transpose();
  MatrixX lower = G.triangularView<Eigen::Lower>();  // only the lower triangle is read
  f.compute(lower);
  for (int m = 0; m <= rows; ++m) {
    SCOPED_TRACE("prefix of " + std::to_string(m) + " rows");
    const MatrixX Jm = J.topRows(m);
    const MatrixX P = priorityProjector(f, J, w_inv, m);
    const MatrixX Pref = m == 0 ? MatrixX(MatrixX::Identity(n, n)) : math::weightedNullSpaceProjector(Jm, MatrixX(w.asDiagonal()), svd_tolerance);
    const double scale = 1.0 + Pref.norm();
    EXPECT_LT((P - Pref).norm() / scale, 1e-8);
    EXPECT_LT((P * P - P).norm() / scale, 1e-8);  // idempotent
    if (m > 0) {
      EXPECT_LT((Jm * P).norm() / (1 + Jm.norm()), 1e-8);  // J Π = 0
      const Eigen::JacobiSVD<MatrixX> svd(Jm * w_inv.cwiseSqrt().asDiagonal());
      int rank = 0;
      for (int i = 0; i < svd.singularValues().size(); ++i)
        if (svd.singularValues()(i) > std::sqrt(svd_tolerance) * svd.singularValues()(0)) ++rank;
      EXPECT_EQ(f.rank(m), rank);
    }
  }
}
}  // namespace

TEST(Projector, LdltEqualsSvdOnRandomFullRank) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.5, 20.0);
  for (int trial = 0; trial < 5; ++trial) {
    const MatrixX J = randomMatrix(12, 20, rng);
    VectorX w(20);
    for (int i = 0; i < 20; ++i) w(i) = u(rng);
    expectSameProjector(J, w, 12);
  }
}

TEST(Projector, LdltEqualsSvdOnRankDeficient) {
  std::mt19937 rng(2);
  MatrixX J = randomMatrix(10, 18, rng);
  J.row(7) = 2.0 * J.row(1) - J.row(3);  // dependent row
  J.row(9).setZero();                    // a disabled frame's row
  VectorX w = VectorX::LinSpaced(18, 1.0, 9.0);
  expectSameProjector(J, w, 8);
}

TEST(Projector, MannequinAllFramesStandingStraightLegs) {
  // the 36 rows of hands, feet, pelvis, head at the standing posture (straight knees): the
  // augmented Jacobian loses rank; both factorizations find the same rank and projector
  const auto& model = male50();
  ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  Controller ctl(model, c);
  ctl.computeFreeMotion();
  const MatrixX& J = ctl.taskJacobian();
  ASSERT_EQ(J.rows(), 36);
  ASSERT_EQ(J.cols(), 43);
  const Eigen::JacobiSVD<MatrixX> svd(J * ctl.frictionDiagonal().cwiseInverse().cwiseSqrt().asDiagonal());
  int rank = 0;
  for (int i = 0; i < svd.singularValues().size(); ++i)
    if (svd.singularValues()(i) > 1e-4 * svd.singularValues()(0)) ++rank;
  EXPECT_LT(rank, 36);
  expectSameProjector(J, ctl.frictionDiagonal(), rank);
}

TEST(PriorityGramFactor, EveryPrefixGivesTheProjectorOfItsRowsOnRandomAndRankDeficientTasks) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.5, 20.0);
  MatrixX J = randomMatrix(12, 20, rng);
  VectorX w(20);
  for (int i = 0; i < 20; ++i) w(i) = u(rng);
  expectPrefixProjectors(J, w, 1e-9);
  // dependent rows (on rows before them and on later rows' predecessors), a zero row (a disabled frame's)
  J.row(7) = 2.0 * J.row(1) - J.row(3);
  J.row(9).setZero();
  J.row(4) = -J.row(0);
  expectPrefixProjectors(J, w, 1e-9);
  PriorityGramFactor f(12, 20, 1e-9);
  f.compute(J * w.cwiseInverse().asDiagonal() * J.transpose());
  EXPECT_EQ(f.rank(12), 9);
  EXPECT_EQ(f.rank(5), 4);  // row 4 = −row 0 is dropped within the first five
  // bad use is refused
  EXPECT_THROW(PriorityGramFactor(3, 5, 1.0), std::invalid_argument);
  EXPECT_THROW(f.compute(MatrixX::Zero(3, 3)), std::invalid_argument);
  VectorX g = VectorX::Ones(20), out;
  EXPECT_THROW(f.projectTorque(J, w, 13, g, out), std::invalid_argument);
}

TEST(PriorityGramFactor, TheAvx2AndPortableUpdatesGiveTheSameBits) {
  // where the CPU has AVX2 the column updates run 4 doubles wide; without FMA they round alike, so both
  // paths project every torque to the same bits (where it has not, both are the portable code)
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.5, 20.0);
  MatrixX J = randomMatrix(36, 43, rng);
  J.row(20) = J.row(3) - 0.5 * J.row(11);  // a dependent row
  VectorX w(43);
  for (int i = 0; i < 43; ++i) w(i) = u(rng);
  const VectorX w_inv = w.cwiseInverse();
  const MatrixX G = J * w_inv.asDiagonal() * J.transpose();
  PriorityGramFactor wide(36, 43, 1e-9, true), portable(36, 43, 1e-9, false);
  wide.compute(G);
  portable.compute(G);
  EXPECT_EQ(wide.rank(36), portable.rank(36));
  EXPECT_EQ(portable.rank(36), 35);
  for (int m : {6, 18, 36}) {
    const VectorX g = randomMatrix(43, 1, rng);
    VectorX a, b;
    wide.projectTorque(J, w_inv, m, g, a);
    portable.projectTorque(J, w_inv, m, g, b);
    EXPECT_EQ(a, b) << "prefix " << m;
  }
}

TEST(PriorityGramFactor, MannequinPrioritisedFramesAtTheStandingPosture) {
  // the controller's J (rows in priority order) at straight knees, where the 36 rows lose rank: every
  // prefix's projector and rank as the SVD of those rows
  const auto& model = male50();
  ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  Controller ctl(model, c);
  ctl.computeFreeMotion();
  expectPrefixProjectors(ctl.taskJacobian(), ctl.frictionDiagonal(), 1e-8);
}

TEST(Projector, EmptyTaskIsIdentity) {
  WeightedNullSpace p(0, 5, ProjectorMethod::kLdlt, 1e-9);
  p.compute(MatrixX(0, 5), VectorX::Ones(5));
  EXPECT_LT((p.matrix() - MatrixX::Identity(5, 5)).norm(), 1e-15);
  EXPECT_THROW(WeightedNullSpace(3, 5, ProjectorMethod::kLdlt, 0.0), std::invalid_argument);
  WeightedNullSpace q(3, 5, ProjectorMethod::kLdlt, 1e-9);
  EXPECT_THROW(q.compute(MatrixX::Zero(2, 5), VectorX::Ones(5)), std::invalid_argument);
}

TEST(AugmentedImpedance, KEqualsBaDecouplesTaskAndInternalDynamics) {
  // (2.42): with K = b_a the off-diagonal block J b_a⁻¹ J_intᵀ vanishes, and Π = N J_int (2.36)
  // is the b_a-weighted projector (2.35), so Γ = JᵀW + ΠᵀΓ_0 = JᵀW + J_intᵀ(NᵀΓ_0) (2.37–2.39)
  std::mt19937 rng(5);
  const MatrixX J = randomMatrix(6, 14, rng);
  const VectorX b_a = VectorX::LinSpaced(14, 0.5, 7.0);
  const AugmentedImpedance ai = augmentedImpedance(J, b_a, 1e-10);
  ASSERT_EQ(ai.N.cols(), 8);
  EXPECT_LT((J * ai.N).norm(), 1e-10);
  const MatrixX off = J * b_a.cwiseInverse().asDiagonal() * ai.J_int.transpose();
  EXPECT_LT(off.norm(), 1e-10);
  WeightedNullSpace p(6, 14, ProjectorMethod::kLdlt, 1e-9);
  p.compute(J, b_a.cwiseInverse());
  EXPECT_LT((ai.N * ai.J_int - p.matrix()).norm(), 1e-9);
  // with another K the block does not vanish
  const VectorX K = VectorX::Ones(14);
  const MatrixX NtK = ai.N.transpose() * K.asDiagonal();
  const MatrixX Jint_other = (NtK * ai.N).llt().solve(NtK);
  EXPECT_GT((J * b_a.cwiseInverse().asDiagonal() * Jint_other.transpose()).norm(), 1e-3);
}
