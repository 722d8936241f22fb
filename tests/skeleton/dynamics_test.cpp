// Inverse dynamics (dynamics.hpp): the recursive Newton–Euler algorithm against hand-derived equations
// of motion (a pendulum, the two-link arm of Spong & Vidyasagar), a torque-free body in flight, and on a
// random tree with every joint type against two independent paths: the kinetic energy from the
// segments' point velocities (vᵀ M v = 2T, M symmetric) and the momentum theorem (the root's wrench is
// the rate of the whole body's spatial momentum minus its weight), differentiated numerically.
#include "mannequin/skeleton/dynamics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mannequin/skeleton/kinematics.hpp"
#include "test_models.hpp"

using namespace mannequin::skeleton;

namespace {

constexpr double kG = 9.81;

Segment segment(const char* name, int joint, double mass, const Vector3& com, const Matrix3& inertia) {
  Segment s;
  s.name = name;
  s.joint = joint;
  s.mass = mass;
  s.com = com;
  s.inertia = inertia;
  return s;
}

// Spatial momentum of the whole tree about the world origin, world frame (angular, linear), summed from
// each segment's CoM velocity (point Jacobian) and angular velocity: an independent path to rnea's.
Vector6 spatialMomentum(const Model& m, Data& d, const VectorX& q, const VectorX& v) {
  computeJointJacobians(m, d, q);
  Vector6 h = Vector6::Zero();
  Matrix3X Jp;
  Matrix6X Jf;
  for (const Segment& s : m.segments) {
    pointJacobian(m, d, s.joint, s.com, Jp);
    jointJacobian(m, d, s.joint, ReferenceFrame::kLocalWorldAligned, Jf);
    const Vector3 c = d.oMi[s.joint].act(s.com);
    const Vector3 vc = Jp * v;
    const Vector3 w = (Jf * v).head<3>();
    const Matrix3 R = d.oMi[s.joint].R;
    h.head<3>() += R * s.inertia * R.transpose() * w + c.cross(s.mass * vc);
    h.tail<3>() += s.mass * vc;
  }
  return h;
}

// The states a time step dt before and after (q0, v0) on the path of constant acceleration a0 (explicit
// Lie–Euler both ways), for central differences along it.
struct StepsAround {
  VectorX qm, vm, qp, vp;
  StepsAround(const Model& m, const VectorX& q0, const VectorX& v0, const VectorX& a0, double dt)
      : qm(integrate(m, q0, v0 - a0 * dt, -dt)), vm(v0 - a0 * dt), qp(integrate(m, q0, v0, dt)), vp(v0 + a0 * dt) {}
};

}  // namespace

TEST(Rnea, PendulumHoldsItsWeightAndAcceleratesItsInertia) {
  // a hinge about x at the origin, a 2 kg bob 0.7 m below it with I_xx = 0.03 about its CoM:
  // τ = (I_xx + m l²) θ̈ + m g l sin θ, whatever θ̇
  Model m;
  m.addJoint("hinge", JointType::kRevolute, -1, SE3::Identity(), Vector3::UnitX());
  const double mass = 2.0, l = 0.7, Ixx = 0.03;
  m.addSegment(segment("bob", 0, mass, Vector3(0, 0, -l), Vector3(Ixx, 0.05, 0.02).asDiagonal()));
  Data d(m);
  for (double th : {0.0, 0.4, -1.2, 2.5}) {
    for (double thd : {0.0, 3.0}) {
      const double thdd = -1.7;
      const VectorX q = VectorX::Constant(1, th), v = VectorX::Constant(1, thd), a = VectorX::Constant(1, thdd);
      const VectorX& tau = rnea(m, d, q, v, a, Vector3(0, 0, -kG));
      EXPECT_NEAR(tau(0), (Ixx + mass * l * l) * thdd + mass * kG * l * std::sin(th), 1e-12) << th << " " << thd;
      // the hinge carries the weight and the bob's centripetal and tangential forces
      const Vector3 c(0, l * std::sin(th), -l * std::cos(th));
      const Vector3 tangent(0, l * std::cos(th), l * std::sin(th));
      const Vector3 f = mass * (thdd * tangent - thd * thd * c + Vector3(0, 0, kG));
      EXPECT_LT((d.joint_wrench[0].tail<3>() - f).norm(), 1e-12);
    }
  }
}

TEST(Rnea, TwoLinkArmMatchesSpongsEquationsOfMotion) {
  // Spong & Vidyasagar, "Robot Dynamics and Control", §6.4: two links in the plane (joints about z),
  // no gravity: τ1 = d11 q̈1 + d12 q̈2 + 2h q̇1 q̇2 + h q̇2², τ2 = d12 q̈1 + d22 q̈2 − h q̇1², h = −m2 l1 lc2 sin q2
  const double l1 = 0.9, lc1 = 0.4, lc2 = 0.35, m1 = 3.0, m2 = 1.5, I1 = 0.2, I2 = 0.07;
  Model m;
  const int j1 = m.addJoint("j1", JointType::kRevolute, -1, SE3::Identity(), Vector3::UnitZ());
  const int j2 = m.addJoint("j2", JointType::kRevolute, j1, SE3(Matrix3::Identity(), Vector3(l1, 0, 0)),
                            Vector3::UnitZ());
  m.addSegment(segment("link1", j1, m1, Vector3(lc1, 0, 0), Vector3(0.01, 0.02, I1).asDiagonal()));
  m.addSegment(segment("link2", j2, m2, Vector3(lc2, 0, 0), Vector3(0.01, 0.02, I2).asDiagonal()));
  Data d(m);
  const VectorX q = (VectorX(2) << 0.3, 1.1).finished();
  const VectorX v = (VectorX(2) << -2.0, 1.5).finished();
  const VectorX a = (VectorX(2) << 0.7, -3.0).finished();
  const double c2 = std::cos(q(1)), h = -m2 * l1 * lc2 * std::sin(q(1));
  const double d11 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2 * l1 * lc2 * c2) + I1 + I2;
  const double d12 = m2 * (lc2 * lc2 + l1 * lc2 * c2) + I2;
  const double d22 = m2 * lc2 * lc2 + I2;
  const VectorX& tau = rnea(m, d, q, v, a, Vector3::Zero());
  EXPECT_NEAR(tau(0), d11 * a(0) + d12 * a(1) + 2 * h * v(0) * v(1) + h * v(1) * v(1), 1e-12);
  EXPECT_NEAR(tau(1), d12 * a(0) + d22 * a(1) - h * v(0) * v(0), 1e-12);
}

TEST(Rnea, ABodyInFlightNeedsNoWrench) {
  // a free flyer with its CoM at the root, spinning about a principal axis: gravity alone moves it, so the
  // root wrench is zero when the CoM falls at g (body frame: v̇ = Rᵀg − ω × v) and ω is constant
  Model m;
  m.addJoint("root", JointType::kFreeFlyer, -1, SE3::Identity());
  m.addSegment(segment("body", 0, 5.0, Vector3::Zero(), Vector3(0.1, 0.2, 0.3).asDiagonal()));
  Data d(m);
  VectorX q(6);
  q << 0.3, -0.2, 1.5, 0.4, -0.7, 0.2;
  const Vector3 w(0, 2.0, 0), vb(1.0, -0.5, 3.0);
  VectorX v(6);
  v << w, vb;
  const Matrix3 R = mannequin::math::expSO3(q.tail<3>());
  const Vector3 g(0, 0, -kG);
  VectorX a(6);
  a << Vector3::Zero(), R.transpose() * g - w.cross(vb);
  const VectorX& tau = rnea(m, d, q, v, a, g);
  EXPECT_LT(tau.norm(), 1e-12);
  EXPECT_LT(d.joint_wrench[0].norm(), 1e-12);
  // at rest it needs its weight, upward, through its CoM
  const VectorX& tau_rest = rnea(m, d, q, VectorX::Zero(6), VectorX::Zero(6), g);
  EXPECT_LT((d.joint_wrench[0] - wrenchAt(q.head<3>(), Vector3(0, 0, 5.0 * kG))).norm(), 1e-12);
  EXPECT_NEAR(tau_rest.tail<3>().norm(), 5.0 * kG, 1e-12);  // the body-frame force
}

TEST(Rnea, RandomTreeMassMatrixIsSymmetricAndGivesTheKineticEnergy) {
  for (unsigned seed : {1u, 7u, 19u}) {
    const Model m = test_models::makeRandomTree(seed, 12);
    Data d(m);
    const VectorX q = test_models::randomConfiguration(m, seed + 100);
    // column k of M: τ for a = e_k, v = 0, no gravity
    mannequin::math::MatrixX M(m.nv, m.nv);
    for (int k = 0; k < m.nv; ++k)
      M.col(k) = rnea(m, d, q, VectorX::Zero(m.nv), VectorX::Unit(m.nv, k), Vector3::Zero());
    EXPECT_LT((M - M.transpose()).norm(), 1e-10 * M.norm()) << seed;
    for (int trial = 0; trial < 3; ++trial) {
      const VectorX v = test_models::randomConfiguration(m, seed * 10 + trial, 2.0);
      const double T = kineticEnergy(m, d, q, v);
      EXPECT_NEAR(v.dot(M * v), 2 * T, 1e-10 * T) << seed;
    }
  }
}

TEST(Rnea, RandomTreeRootWrenchIsTheRateOfMomentumMinusTheWeight) {
  // along q(t) = q0 ⊕ (v t + ½ a t²) advanced in small steps: ḣ by central differences of the momentum
  // summed from the segments, against rnea's root wrench plus the weight's wrench
  const Vector3 g(0, 0, -kG);
  for (unsigned seed : {2u, 5u}) {
    const Model m = test_models::makeRandomTree(seed, 10);
    Data d(m);
    const VectorX q0 = test_models::randomConfiguration(m, seed + 30);
    const VectorX v0 = test_models::randomConfiguration(m, seed + 40, 1.5);
    const VectorX a0 = test_models::randomConfiguration(m, seed + 50, 3.0);
    const double dt = 1e-6;
    const StepsAround x(m, q0, v0, a0, dt);
    const Vector6 hdot = (spatialMomentum(m, d, x.qp, x.vp) - spatialMomentum(m, d, x.qm, x.vm)) / (2 * dt);
    rnea(m, d, q0, v0, a0, g);
    const Vector6 root = d.joint_wrench[0];
    Vector6 weight = Vector6::Zero();
    centerOfMass(m, d);
    for (std::size_t s = 0; s < m.segments.size(); ++s) weight += wrenchAt(d.segment_com[s], m.segments[s].mass * g);
    EXPECT_LT((root + weight - hdot).norm(), 1e-4 * hdot.norm() + 1e-4) << seed << "\nroot+weight "
        << (root + weight).transpose() << "\nhdot " << hdot.transpose();
  }
}

TEST(Rnea, RandomTreePowerIsTheRateOfEnergy) {
  // τᵀv = d/dt (T + U), U = −Σ m g·c: checks the velocity-product terms C(q, v) v and gravity together
  const Vector3 g(0, 0, -kG);
  for (unsigned seed : {3u, 8u}) {
    const Model m = test_models::makeRandomTree(seed, 10);
    Data d(m);
    const VectorX q0 = test_models::randomConfiguration(m, seed + 60);
    const VectorX v0 = test_models::randomConfiguration(m, seed + 70, 1.5);
    const VectorX a0 = test_models::randomConfiguration(m, seed + 80, 3.0);
    const auto energy = [&](const VectorX& q, const VectorX& v) {
      double E = kineticEnergy(m, d, q, v);
      centerOfMass(m, d);
      for (std::size_t s = 0; s < m.segments.size(); ++s) E -= m.segments[s].mass * g.dot(d.segment_com[s]);
      return E;
    };
    const double dt = 1e-6;
    const StepsAround x(m, q0, v0, a0, dt);
    const double Edot = (energy(x.qp, x.vp) - energy(x.qm, x.vm)) / (2 * dt);
    const double power = rnea(m, d, q0, v0, a0, g).dot(v0);
    EXPECT_NEAR(power, Edot, 1e-4 * std::abs(Edot) + 1e-4) << seed;
  }
}

TEST(Rnea, ExternalWrenchesAreSubtractedThroughTheJacobianTranspose) {
  // τ(f_ext) = τ(0) − J_iᵀ f_ext,i for a wrench on one joint's body
  const Model m = test_models::makeRandomTree(4, 8);
  Data d(m);
  const VectorX q = test_models::randomConfiguration(m, 90);
  const VectorX v = test_models::randomConfiguration(m, 91);
  const VectorX a = test_models::randomConfiguration(m, 92);
  const VectorX tau0 = rnea(m, d, q, v, a, Vector3(0, 0, -kG));
  std::vector<Vector6> fext(m.joints.size(), Vector6::Zero());
  const int body = 5;
  fext[body] = wrenchAt(Vector3(0.2, -0.1, 0.4), Vector3(3.0, -1.0, 20.0));
  const VectorX tau1 = rnea(m, d, q, v, a, Vector3(0, 0, -kG), &fext);
  Matrix6X J;
  jointJacobian(m, d, body, ReferenceFrame::kWorld, J);
  EXPECT_LT((tau1 - (tau0 - J.transpose() * fext[body])).norm(), 1e-10 * tau0.norm());
  // a wrench list of the wrong size is refused with the name of what is wrong
  // (MANNEQUIN_CHECK_ARGUMENT_SIZE: the function, what, what it got and what was expected)
  const auto refusal = [](auto&& call) -> std::string {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  std::vector<Vector6> short_list(2, Vector6::Zero());
  EXPECT_EQ(refusal([&] { rnea(m, d, q, v, a, Vector3::Zero(), &short_list); }),
            "rnea: external wrenches fext has size 2, expected " + std::to_string(m.joints.size()));
  EXPECT_EQ(refusal([&] { rnea(m, d, q, v.head(3), a, Vector3::Zero()); }),
            "rnea: velocity v has size 3, expected " + std::to_string(m.nv));
}

TEST(SpatialForce, WrenchAtAndMomentAboutAreInverse) {
  const Vector3 p(1, 2, 3), f(-4, 5, 0.5);
  const Vector6 w = wrenchAt(p, f);
  EXPECT_LT(momentAbout(w, p).norm(), 1e-14);
  EXPECT_LT((momentAbout(w, Vector3::Zero()) - p.cross(f)).norm(), 1e-14);
}
