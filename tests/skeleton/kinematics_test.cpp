#include "mannequin/skeleton/kinematics.hpp"

#include <gtest/gtest.h>

#include "test_models.hpp"

using namespace mannequin::skeleton;
using mannequin::math::expSE3;
using mannequin::math::logSE3;
using mannequin::math::logSO3;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kEps = 1e-6;   // finite-difference step
constexpr double kTol = 1e-7;   // central differences: error O(ε²) plus round-off O(1e-16/ε)

struct Fk {
  const Model& m;
  Data d;
  explicit Fk(const Model& model) : m(model), d(model) {}
  const Data& at(const VectorX& q) {
    forwardKinematics(m, d, q);
    computeJointJacobians(m, d);
    jacobianCenterOfMass(m, d);
    return d;
  }
};

VectorX step(const Model& m, const VectorX& q, int k, double h) {
  VectorX v = VectorX::Zero(m.nv);
  v(k) = h;
  return integrate(m, q, v);
}
}  // namespace

TEST(Kinematics, TwoLinkPlanarArmByHand) {
  // two revolute joints about z, links of 1 and 0.5 along x: end at (cos a + 0.5 cos(a+b), sin a + 0.5 sin(a+b))
  Model m;
  const int j1 = m.addJoint("j1", JointType::kRevolute, -1, SE3::Identity(), Vector3::UnitZ());
  const int j2 = m.addJoint("j2", JointType::kRevolute, j1, SE3(Matrix3::Identity(), Vector3(1, 0, 0)), Vector3::UnitZ());
  m.addFrame("tip", j2, SE3(Matrix3::Identity(), Vector3(0.5, 0, 0)));
  Data d(m);
  VectorX q(2);
  q << 0.3, -0.7;
  forwardKinematics(m, d, q);
  const Vector3 expected(std::cos(0.3) + 0.5 * std::cos(-0.4), std::sin(0.3) + 0.5 * std::sin(-0.4), 0);
  EXPECT_TRUE(d.oMf[0].p.isApprox(expected, 1e-14));
  EXPECT_NEAR(logSO3(d.oMf[0].R).z(), -0.4, 1e-14);
  // planar Jacobian of the tip by hand: ∂x/∂q1 = −y, ∂y/∂q1 = x; ∂/∂q2 about the elbow
  computeJointJacobians(m, d);
  Matrix3X Jp;
  pointJacobian(m, d, j2, Vector3(0.5, 0, 0), Jp);
  const Vector3 elbow(std::cos(0.3), std::sin(0.3), 0);
  EXPECT_NEAR(Jp(0, 0), -expected.y(), 1e-14);
  EXPECT_NEAR(Jp(1, 0), expected.x(), 1e-14);
  EXPECT_NEAR(Jp(0, 1), -(expected - elbow).y(), 1e-14);
  EXPECT_NEAR(Jp(1, 1), (expected - elbow).x(), 1e-14);
}

TEST(Kinematics, ProductOfExponentialsInWorldTwists) {
  // thesis 1.14: oMi(q) = Π_k exp(ξ_k(0) q_k) · oMi(0), with ξ_k(0) the joint twists in the world at q = 0
  Model m;
  int parent = -1;
  std::mt19937 g(5);
  std::normal_distribution<double> n;
  for (int i = 0; i < 6; ++i) {
    const SE3 placement(mannequin::math::expSO3(Vector3(n(g), n(g), n(g))), Vector3(n(g), n(g), n(g)));
    parent = m.addJoint("j" + std::to_string(i), JointType::kRevolute, parent, placement, Vector3(n(g), n(g), n(g)));
  }
  Data d0(m), d(m);
  computeJointJacobians(m, d0, VectorX::Zero(m.nq));
  const VectorX q = test_models::randomConfiguration(m, 9, 2.0);
  forwardKinematics(m, d, q);
  SE3 product = SE3::Identity();
  for (int k = 0; k < m.nv; ++k) product = product * expSE3(d0.J.col(k) * q(k));
  EXPECT_TRUE((product * d0.oMi.back()).isApprox(d.oMi.back(), 1e-12));
}

TEST(Kinematics, FrameJacobiansMatchFiniteDifferencesForEveryJointType) {
  const Model m = test_models::makeRandomTree(3);
  ASSERT_EQ(m.joints[0].type, JointType::kFreeFlyer);
  Fk fk(m), plus(m), minus(m);
  for (unsigned seed : {1u, 2u, 3u}) {
    const VectorX q = test_models::randomConfiguration(m, seed, 1.5);
    fk.at(q);
    for (size_t f = 0; f < m.frames.size(); ++f) {
      Matrix6X Jw, Jl, Ja;
      frameJacobian(m, fk.d, static_cast<int>(f), ReferenceFrame::kWorld, Jw);
      frameJacobian(m, fk.d, static_cast<int>(f), ReferenceFrame::kLocal, Jl);
      frameJacobian(m, fk.d, static_cast<int>(f), ReferenceFrame::kLocalWorldAligned, Ja);
      for (int k = 0; k < m.nv; ++k) {
        const SE3 Hp = plus.at(step(m, q, k, kEps)).oMf[f];
        const SE3 Hm = minus.at(step(m, q, k, -kEps)).oMf[f];
        // body twist: log(H⁻¹ H(q ⊕ ε e_k)) / ε (central)
        const Vector6 body = (logSE3(fk.d.oMf[f].inverse() * Hp) - logSE3(fk.d.oMf[f].inverse() * Hm)) / (2 * kEps);
        // spatial twist: log(H(q ⊕ ε e_k) H⁻¹) / ε
        const Vector6 spatial = (logSE3(Hp * fk.d.oMf[f].inverse()) - logSE3(Hm * fk.d.oMf[f].inverse())) / (2 * kEps);
        // world-aligned at the origin: world angular velocity and origin velocity
        Vector6 aligned;
        aligned << spatial.head<3>(), (Hp.p - Hm.p) / (2 * kEps);
        EXPECT_LT((Jl.col(k) - body).norm(), kTol) << "frame " << f << " column " << k;
        EXPECT_LT((Jw.col(k) - spatial).norm(), kTol) << "frame " << f << " column " << k;
        EXPECT_LT((Ja.col(k) - aligned).norm(), kTol) << "frame " << f << " column " << k;
      }
    }
  }
}

TEST(Kinematics, PointAndCenterOfMassJacobiansMatchFiniteDifferences) {
  const Model m = test_models::makeRandomTree(8, 15);
  Fk fk(m), plus(m), minus(m);
  const VectorX q = test_models::randomConfiguration(m, 4, 1.5);
  fk.at(q);
  const Vector3 point(0.1, -0.3, 0.25);
  for (size_t j = 0; j < m.joints.size(); ++j) {
    Matrix3X Jp;
    pointJacobian(m, fk.d, static_cast<int>(j), point, Jp);
    for (int k = 0; k < m.nv; ++k) {
      const Vector3 xp = plus.at(step(m, q, k, kEps)).oMi[j].act(point);
      const Vector3 xm = minus.at(step(m, q, k, -kEps)).oMi[j].act(point);
      EXPECT_LT((Jp.col(k) - (xp - xm) / (2 * kEps)).norm(), kTol) << "joint " << j << " column " << k;
    }
  }
  for (int k = 0; k < m.nv; ++k) {
    const Vector3 cp = plus.at(step(m, q, k, kEps)).com;
    const Vector3 cm = minus.at(step(m, q, k, -kEps)).com;
    EXPECT_LT((fk.d.Jcom.col(k) - (cp - cm) / (2 * kEps)).norm(), kTol) << "column " << k;
  }
}

TEST(Kinematics, CenterOfMassJacobianEqualsMassWeightedPointJacobians) {
  // (3.32): J_com = Σ m_i J_{com_i} / Σ m_i — the O(nv) subtree algorithm against the definition
  const Model m = test_models::makeRandomTree(21, 14);
  Fk fk(m);
  fk.at(test_models::randomConfiguration(m, 6));
  Matrix3X sum = Matrix3X::Zero(3, m.nv), Jp;
  Vector3 com = Vector3::Zero();
  for (const Segment& s : m.segments) {
    pointJacobian(m, fk.d, s.joint, s.com, Jp);
    sum += s.mass * Jp;
    com += s.mass * fk.d.oMi[s.joint].act(s.com);
  }
  EXPECT_TRUE(fk.d.Jcom.isApprox(sum / m.totalMass(), 1e-12));
  EXPECT_TRUE(fk.d.com.isApprox(com / m.totalMass(), 1e-12));
}

TEST(Kinematics, IntegrateAndDifferenceAreInverse) {
  const Model m = test_models::makeRandomTree(13);
  const VectorX q0 = test_models::randomConfiguration(m, 1, 1.0);
  const VectorX v = test_models::randomConfiguration(m, 2, 0.8);
  const VectorX q1 = integrate(m, q0, v);
  EXPECT_LT((difference(m, q0, q1) - v).norm(), 1e-10);
  EXPECT_TRUE(integrate(m, q0, VectorX::Zero(m.nv)).isApprox(q0, 1e-14));
  // integrate(q, v, dt) == integrate(q, v·dt)
  EXPECT_TRUE(integrate(m, q0, v, 0.01).isApprox(integrate(m, q0, v * 0.01), 1e-14));
}

TEST(Kinematics, BallJointVelocityIsBodyAngularVelocity) {
  // a ball joint's Jacobian columns are its child frame axes (Annex D.1 exp-map parameterisation)
  Model m;
  const int b = m.addJoint("ball", JointType::kBall, -1, SE3::Identity());
  m.addFrame("f", b, SE3::Identity());
  Data d(m);
  VectorX q(3);
  q << 0.2, -1.1, 0.4;
  computeJointJacobians(m, d, q);
  EXPECT_TRUE(d.J.topRows<3>().isApprox(mannequin::math::expSO3(q.head<3>()), 1e-14));
  // near π the parameterisation still works through integrate
  VectorX qpi(3);
  qpi << kPi - 1e-7, 0, 0;
  VectorX v(3);
  v << 0, 0.01, 0;
  const VectorX q1 = integrate(m, qpi, v);
  EXPECT_LE(q1.norm(), kPi + 1e-12);
  EXPECT_LT((difference(m, qpi, q1) - v).norm(), 1e-9);
}

TEST(Kinematics, SizeMismatchAndBadIndicesThrow) {
  const Model m = test_models::makeRandomTree(2, 5);
  Data d(m);
  EXPECT_THROW(forwardKinematics(m, d, VectorX::Zero(m.nq + 1)), std::invalid_argument);
  EXPECT_THROW(integrate(m, VectorX::Zero(m.nq), VectorX::Zero(3)), std::invalid_argument);
  computeJointJacobians(m, d, VectorX::Zero(m.nq));
  Matrix6X J;
  EXPECT_THROW(frameJacobian(m, d, 99, ReferenceFrame::kWorld, J), std::invalid_argument);
  Matrix3X Jp;
  EXPECT_THROW(pointJacobian(m, d, -1, Vector3::Zero(), Jp), std::invalid_argument);
}
