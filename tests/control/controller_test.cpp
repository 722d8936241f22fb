// The controller on the male_50th mannequin: Jacobians, b (2.17), the constraint hook (Alg. 4),
// door-handle reach (Fig. 2.6), conflicting tasks by weights and priorities (Fig. 2.11, 2.13,
// 2.14), gravity and the internal potential (Fig. 4.2), bad input.
#include <gtest/gtest.h>

#include <random>

#include "common.hpp"

using namespace mannequin;
using namespace mannequin::control;
using namespace mannequin::control::testing;

namespace {
// posture error over the internal coordinates: ‖q_d ⊖ q‖ without the root
double postureError(const skeleton::Model& model, const VectorX& q, const VectorX& q_d) {
  VectorX d(model.nv);
  differenceInPlace(model, q, q_d, d);
  return d.tail(model.nv - 6).norm();
}
}  // namespace

TEST(Controller, DefaultConfigBuildsAndHoldsThePostureWithoutGravity) {
  ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  c.gravity.setZero();
  Controller ctl(male50(), c);
  ASSERT_EQ(ctl.numFrames(), 6);
  const VectorX q0 = ctl.q();
  for (int i = 0; i < 100; ++i) ASSERT_EQ(ctl.step(), StepStatus::kOk);
  EXPECT_LT((ctl.q() - q0).cwiseAbs().maxCoeff(), 1e-9);  // targets at the current poses: equilibrium
  for (const auto& e : ctl.checkStability()) EXPECT_LT(e.ratio, 1.0) << e.what;
}

TEST(Controller, ControlFrameJacobianMatchesFiniteDifferences) {
  // body Jacobian of a control frame with an offset: V = J q̇ with e = log(oMc(q)⁻¹ oMc(q ⊕ εe_k))/ε
  const auto& model = male50();
  ControllerConfig c = baseConfig();
  ControlFrameConfig hand = frameConfig("hand_r", 0, 10, 100);
  hand.offset = SE3(rotation(Vector3(0.3, -0.5, 0.2)), Vector3(0.02, -0.01, -0.09));
  c.frames = {hand, frameConfig("foot_l", 1, 10, 100)};
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  VectorX q(model.nq);
  for (int i = 0; i < model.nq; ++i) q(i) = u(rng);
  Controller ctl(model, c, q);
  ctl.computeFreeMotion();
  const int h = ctl.frameIndex("hand_r");
  const MatrixX J = ctl.taskJacobian().middleRows(ctl.frameRow(h), 6);
  skeleton::Data data(model);
  const auto pose = [&](const VectorX& qq) {
    skeleton::forwardKinematics(model, data, qq);
    return data.oMf[model.frameIndex("hand_r")] * hand.offset;
  };
  const SE3 H0 = pose(q);
  EXPECT_TRUE(H0.isApprox(ctl.frame(h).pose, 1e-12));
  const double eps = 1e-7;
  for (int k = 0; k < model.nv; ++k) {
    VectorX v = VectorX::Zero(model.nv);
    v(k) = eps;
    const Vector6 fd = math::logSE3(H0.inverse() * pose(skeleton::integrate(model, q, v))) / eps;
    EXPECT_LT((fd - J.col(k)).norm(), 1e-5) << "column " << k;
  }
}

TEST(Controller, ApparentFrictionIsBaPlusJtBcJ) {
  // b = b_a + Σ Jᵀ b_c J (2.17), symmetric positive definite
  ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  Controller ctl(male50(), c);
  ctl.computeFreeMotion();
  MatrixX b = ctl.frictionDiagonal().asDiagonal();
  for (int i = 0; i < ctl.numFrames(); ++i) {
    const MatrixX Ji = ctl.taskJacobian().middleRows(ctl.frameRow(i), 6);
    b += Ji.transpose() * ctl.frame(i).damping.asDiagonal() * Ji;
  }
  EXPECT_LT((b - ctl.apparentFriction()).norm() / b.norm(), 1e-14);
  // b has the sparsity of the tree of coordinates, so its LᵀL factor along the tree (no fill-in) is
  // exact: LᵀL reproduces every entry of b, the ones off the pattern included
  const auto& f = ctl.apparentFrictionFactor();
  ASSERT_EQ(f.info(), Eigen::Success);
  EXPECT_LT((f.matrixL().transpose() * f.matrixL() - b).norm() / b.norm(), 1e-14);
  int zeros = 0;  // and the pattern is sparse: the legs' coordinates do not couple with the arms'
  for (Eigen::Index i = 0; i < b.rows(); ++i)
    for (Eigen::Index j = 0; j < i; ++j) zeros += b(i, j) == 0.0 ? 1 : 0;
  EXPECT_GT(zeros, b.rows() * (b.rows() - 1) / 4);
  // q̇_free = b⁻¹Γ
  const VectorX gamma = ctl.taskTorque() + ctl.internalTorque() + ctl.gravityTorque();
  EXPECT_LT((b * ctl.qdotFree() - gamma).norm(), 1e-9 * (1 + gamma.norm()));
}

TEST(Controller, ConstraintHookAddsBInverseJcTWcThenIntegratesOnTheManifold) {
  const auto& model = male50();
  ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  Controller ctl(model, c);
  ctl.step();
  const VectorX q0 = ctl.q();
  ASSERT_EQ(ctl.computeFreeMotion(), StepStatus::kOk);
  // a contact-like force: W_c = 50 N up on the left sole point, Γ_c = J_cᵀW_c (3.7)
  Eigen::Matrix3Xd Jc;
  skeleton::pointJacobian(model, ctl.data(), model.frames[model.frameIndex("sole_l")].joint,
                          model.frames[model.frameIndex("sole_l")].placement.p, Jc);
  const VectorX gamma_c = Jc.transpose() * Vector3(0, 0, 50);
  ctl.applyConstraintForce(gamma_c);
  const VectorX expected = ctl.qdotFree() + ctl.apparentFriction().ldlt().solve(gamma_c);
  EXPECT_LT((ctl.qdot() - expected).norm(), 1e-10 * (1 + expected.norm()));
  // the sole moves up relative to the free motion
  EXPECT_GT((Jc * (ctl.qdot() - ctl.qdotFree()))(2), 0.0);
  const VectorX qdot = ctl.qdot();
  ctl.integrate();
  EXPECT_LT((ctl.q() - skeleton::integrate(model, q0, qdot, c.dt)).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_NEAR(ctl.constraintPort().power, gamma_c.dot(qdot), 1e-12);  // Γ_cᵀq̇ at the constraint port
  EXPECT_EQ(ctl.applyConstraintForce(gamma_c), ForceStatus::kNoFreeMotion);  // stage 1 not run: refused
  EXPECT_THROW(ctl.applyConstraintForce(VectorX::Zero(model.nv + 1)), std::invalid_argument);  // a size other than nv
  VectorX nan_gamma = gamma_c;
  nan_gamma(7) = std::nan("");
  ASSERT_EQ(ctl.computeFreeMotion(), StepStatus::kOk);
  const VectorX before = ctl.qdot();
  EXPECT_EQ(ctl.applyConstraintForce(nan_gamma), ForceStatus::kNonFinite);
  EXPECT_EQ((ctl.qdot() - before).cwiseAbs().maxCoeff(), 0.0);  // refused: q̇ unchanged
}

TEST(Controller, DoorHandleReachConvergesMonotonically) {
  // Fig. 2.6: the target follows a trajectory to the door handle, the hand's PD coupling follows it;
  // once the target stops, the error decays monotonically (free case: no conflict, no weight)
  const auto& model = male50();
  ControllerConfig c = baseConfig();
  c.frames = {frameConfig("foot_l", 0, 2000, 20000), frameConfig("foot_r", 0, 2000, 20000),
              frameConfig("hand_r", 1, 100, 2000)};
  Controller ctl(model, c);
  const int h = ctl.frameIndex("hand_r");
  const SE3 start = ctl.frame(h).pose;
  // the handle: 30 cm forward, 15 cm up, hand pitched forward by 60°
  const SE3 handle(rotation(Vector3(0, -60.0 * M_PI / 180, 0)) * start.R, start.p + Vector3(0.30, -0.05, 0.15));
  const int approach = 500, hold = 2500;
  for (int i = 1; i <= approach; ++i) {
    ctl.setTarget(h, math::interpolate(start, handle, static_cast<double>(i) / approach));
    ASSERT_EQ(ctl.step(), StepStatus::kOk);
  }
  ctl.computeFreeMotion();
  double prev = ctl.frame(h).error.norm();
  const double after_approach = prev;
  int increases = 0;
  for (int i = 0; i < hold; ++i) {
    ASSERT_EQ(ctl.step(), StepStatus::kOk);
    ctl.computeFreeMotion();
    const double e = ctl.frame(h).error.norm();
    if (e > prev + 1e-12) ++increases;
    prev = e;
  }
  std::printf("door handle: error %.4f after the approach, %.2e m / %.2e rad after %.1f s more\n", after_approach,
              ctl.frame(h).positionError(), ctl.frame(h).rotationError(), hold * 1e-3);
  EXPECT_EQ(increases, 0);
  EXPECT_GT(after_approach, 1e-3);  // there was something left to converge
  EXPECT_LT(ctl.frame(h).positionError(), 1e-4);
  EXPECT_LT(ctl.frame(h).rotationError(), 1e-3);
  // feet held
  EXPECT_LT(ctl.frame(ctl.frameIndex("foot_l")).positionError(), 1e-4);
}

namespace {
struct ConflictResult {
  double foot, hand, hand_null_force, hand_force;
};
ConflictResult runConflict(bool priorities) {
  // Fig. 2.11: the feet hold their standing poses, the right hand is asked 2.5 m in front at
  // 1.2 m height, farther than the stretched body reaches: not both reachable
  const auto& model = male50();
  ControllerConfig c = baseConfig();
  c.frames = {frameConfig("foot_l", 0, 2000, 20000), frameConfig("foot_r", 0, 2000, 20000),
              frameConfig("hand_r", priorities ? 1 : 0, 100, 2000)};
  c.frames[2].stiffness.head<3>().setZero();  // position only for the hand
  c.frames[2].damping.head<3>().setZero();
  Controller ctl(model, c);
  const int h = ctl.frameIndex("hand_r"), fl = ctl.frameIndex("foot_l"), fr = ctl.frameIndex("foot_r");
  SE3 target = ctl.frame(h).pose;
  target.p = Vector3(2.5, -0.2, 1.2);
  ctl.setTarget(h, target);
  for (int i = 0; i < 3000; ++i) ctl.step();
  ctl.computeFreeMotion();
  ConflictResult r;
  r.foot = std::max(ctl.frame(fl).error.norm(), ctl.frame(fr).error.norm());
  r.hand = ctl.frame(h).positionError();
  // optimality of the lower task: its torque has no component left in the feet's null space
  const MatrixX& J = ctl.taskJacobian();
  const MatrixX Jh = J.middleRows(ctl.frameRow(h), 6);
  const VectorX gamma_h = Jh.transpose() * ctl.frame(h).stiffness.cwiseProduct(ctl.frame(h).error);
  MatrixX Jfeet(12, model.nv);
  Jfeet << J.middleRows(ctl.frameRow(fl), 6), J.middleRows(ctl.frameRow(fr), 6);
  WeightedNullSpace feet(12, model.nv, ProjectorMethod::kSvd, 1e-9);
  feet.compute(Jfeet, ctl.frictionDiagonal().cwiseInverse());
  VectorX projected(model.nv);
  feet.projectTorque(gamma_h, projected);
  r.hand_null_force = projected.norm();
  r.hand_force = gamma_h.norm();
  return r;
}
}  // namespace

TEST(Controller, ConflictingTasksWeightedNeitherIsMet) {
  // Fig. 2.13: weighting (same level, different stiffnesses): a compromise, no task met
  const ConflictResult w = runConflict(false);
  EXPECT_GT(w.foot, 0.01);
  EXPECT_GT(w.hand, 0.01);
}

TEST(Controller, ConflictingTasksPrioritisedTopIsMetLowerAsCloseAsPossible) {
  // Fig. 2.14: the feet (top) are met, the hand is as close as it can be without moving them
  const ConflictResult w = runConflict(false);
  const ConflictResult p = runConflict(true);
  std::printf("weighted: foot %.4f m, hand %.3f m; priorities: foot %.2e m, hand %.3f m, null-space force %.2e of %.1f\n",
              w.foot, w.hand, p.foot, p.hand, p.hand_null_force, p.hand_force);
  EXPECT_LT(p.foot, 1e-4);
  EXPECT_GT(p.hand, w.hand);  // the hand no longer drags the feet along
  EXPECT_LT(p.hand_null_force, 1e-3 * p.hand_force);
}

namespace {
double sag(bool gravity, bool internal) {
  // Fig. 4.2: hands and feet held at their standing poses (4 control frames, as in 2.2.1.4)
  const auto& model = male50();
  ControllerConfig c = baseConfig();
  if (gravity) c.gravity = Vector3(0, 0, -9.81);
  c.internal.enabled = internal;
  c.internal.stiffness = 400;
  c.frames = {frameConfig("foot_l", 0, 2000, 20000), frameConfig("foot_r", 0, 2000, 20000),
              frameConfig("hand_l", 0, 100, 2000), frameConfig("hand_r", 0, 100, 2000)};
  Controller ctl(model, c);
  const VectorX q_d = ctl.posture();
  for (int i = 0; i < 2000; ++i) ctl.step();
  return postureError(model, ctl.q(), q_d);
}
}  // namespace

TEST(Controller, GravitySagsTheMannequinAndTheInternalPotentialRestoresIt) {
  const double none = sag(false, false), slumped = sag(true, false), restored = sag(true, true);
  std::printf("posture error (rad): no weight %.2e, weight %.3f, weight + internal potential %.3f\n", none, slumped,
              restored);
  EXPECT_LT(none, 1e-9);       // a) without weight
  EXPECT_GT(slumped, 0.3);     // b) with weight the body slumps (rad, all internal coordinates)
  EXPECT_LT(restored, 0.25 * slumped);  // c) the internal potential gives back the posture
}

TEST(Controller, NaNTargetIsRejectedAndTheStateKept) {
  ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  Controller a(male50(), c), b(male50(), c);
  const int h = a.frameIndex("hand_l");
  SE3 good = a.frame(h).pose;
  good.p.x() += 0.05;
  a.setTarget(h, good);
  b.setTarget(h, good);
  SE3 bad = good;
  bad.p.y() = std::nan("");
  EXPECT_EQ(a.setTarget(h, bad), TargetStatus::kNonFinite);  // refused in the loop, never thrown
  Vector6 twist = Vector6::Zero();
  twist(2) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(a.setTarget(h, good, twist), TargetStatus::kNonFinite);
  SE3 skew = good;
  skew.R(0, 1) += 0.3;
  EXPECT_EQ(a.setTarget(h, skew), TargetStatus::kNotRotation);
  EXPECT_EQ(a.setTarget(h, good), TargetStatus::kOk);
  for (int i = 0; i < 50; ++i) {
    a.step();
    b.step();
  }
  EXPECT_EQ((a.q() - b.q()).cwiseAbs().maxCoeff(), 0.0);  // same as if the bad call never happened
  EXPECT_TRUE(a.frame(h).target.isApprox(good));
  VectorX nan_q = a.q();
  nan_q(10) = std::nan("");
  EXPECT_THROW(a.setPosture(nan_q), std::invalid_argument);
  EXPECT_THROW(a.reset(nan_q), std::invalid_argument);
  EXPECT_THROW(a.frameIndex("hand_x"), std::invalid_argument);
  EXPECT_THROW(a.setTarget(17, good), std::invalid_argument);
  EXPECT_THROW(a.mechanism(h), std::invalid_argument);
}

TEST(Controller, UnknownNamesAndInconsistentConfigsGiveClearErrors) {
  const auto& model = male50();
  const auto message = [&](const ControllerConfig& c) {
    try {
      Controller ctl(model, c);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  ControllerConfig c = parseControllerConfig(
      "control_frames:\n  - name: grip\n    frame: handx\n    stiffness: [1, 1, 1, 10, 10, 10]\n", "test.yaml");
  std::string m = message(c);
  EXPECT_NE(m.find("test.yaml:2"), std::string::npos) << m;
  EXPECT_NE(m.find("'handx'"), std::string::npos) << m;
  EXPECT_NE(m.find("hand_r"), std::string::npos) << m;  // lists the valid frames

  c = baseConfig();
  c.b_a.coordinates["kneee_l"] = 3;
  m = message(c);
  EXPECT_NE(m.find("kneee_l"), std::string::npos) << m;
  EXPECT_NE(m.find("knee_l"), std::string::npos) << m;

  c = baseConfig();
  c.frames = {frameConfig("hand_r", 0, 1, 1), frameConfig("hand_r", 1, 1, 1)};
  EXPECT_NE(message(c).find("duplicate"), std::string::npos);
  c = baseConfig();
  c.frames = {frameConfig("hand_r", 0, 1, 1)};
  c.frames[0].stiffness(2) = -1;
  EXPECT_NE(message(c).find(">= 0"), std::string::npos);
  c = baseConfig();
  c.dt = 0;
  EXPECT_NE(message(c).find("dt_s"), std::string::npos);
  c = baseConfig();
  c.b_a.joints = -2;
  EXPECT_NE(message(c).find("b_a"), std::string::npos);
  c = baseConfig();
  EXPECT_THROW(Controller(model, c, VectorX::Zero(5)), std::invalid_argument);
}

TEST(Controller, WithoutControlFramesTheWeightSinksTheRootAtMgOverB) {
  // hand check of (2.4) with gravity only: b = b_a diagonal, so the root's vertical velocity is
  // −M g / b_root_linear, here −78.5·9.81/300 = −2.567 m/s
  ControllerConfig c = baseConfig();
  c.gravity = Vector3(0, 0, -9.81);
  c.internal.enabled = false;
  Controller ctl(male50(), c);
  ASSERT_EQ(ctl.computeFreeMotion(), StepStatus::kOk);
  EXPECT_NEAR(ctl.qdot()(5), -male50().totalMass() * 9.81 / 300.0, 1e-9);
  EXPECT_NEAR(ctl.qdot()(3), 0.0, 1e-12);
  EXPECT_EQ(ctl.taskJacobian().rows(), 0);
  ctl.integrate();
  EXPECT_NEAR(ctl.q()(2) - skeleton::standingConfiguration(male50())(2), -male50().totalMass() * 9.81 / 300.0 * 1e-3, 1e-12);
  EXPECT_NEAR(ctl.gravityPort().energy, ctl.dissipation().energy, 1e-12);  // the weight's work is dissipated
}

TEST(Controller, CouplingErrorFormsAgreeToFirstOrderAndBothReach) {
  // log(H⁻¹H_d) (thesis) and (log(RᵀR_d), Rᵀ(p_d − p)) differ at second order only
  const SE3 H(rotation(Vector3(0.3, -0.2, 0.5)), Vector3(0.1, 0.2, 0.9));
  for (double s : {1e-2, 1e-3}) {
    const SE3 Hd = H * math::expSE3((Vector6() << 0.4, -0.3, 0.2, 0.5, 0.1, -0.6).finished() * s);
    const Vector6 a = couplingError(H, Hd, CouplingError::kSE3), b = couplingError(H, Hd, CouplingError::kR3SO3);
    EXPECT_LT((a - b).norm(), 2 * s * s);
    EXPECT_LT((a - math::logSE3(H.inverse() * Hd)).norm(), 1e-15);
  }
  // the door-handle reach converges with the thesis's se(3) error too
  ControllerConfig c = baseConfig();
  c.coupling_error = CouplingError::kSE3;
  c.frames = {frameConfig("foot_l", 0, 2000, 20000), frameConfig("foot_r", 0, 2000, 20000),
              frameConfig("hand_r", 1, 100, 2000)};
  Controller ctl(male50(), c);
  const int h = ctl.frameIndex("hand_r");
  const SE3 start = ctl.frame(h).pose;
  ctl.setTarget(h, SE3(rotation(Vector3(0, -0.5, 0)) * start.R, start.p + Vector3(0.2, 0.0, 0.1)));
  for (int i = 0; i < 3000; ++i) ctl.step();
  ctl.computeFreeMotion();
  EXPECT_LT(ctl.frame(h).error.norm(), 1e-6);
}

//---- joint coupling (thesis 4.4.2): Γ_j = k∘(q_j ⊖ q) − b∘q̇_prev, added to Γ unprojected ----

namespace {
Matrix3 rotationOf(const Vector3& v) {  // exp of a rotation vector, by Eigen (not the library's expSO3)
  return v.norm() == 0 ? Matrix3::Identity() : Eigen::AngleAxisd(v.norm(), v.normalized()).toRotationMatrix();
}
Vector3 rotationVector(const Matrix3& R) {  // log, by Eigen
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}
int firstJoint(const skeleton::Model& m, skeleton::JointType type) {
  for (std::size_t j = 0; j < m.joints.size(); ++j)
    if (m.joints[j].type == type) return static_cast<int>(j);
  ADD_FAILURE() << "no joint of type " << skeleton::toString(type);
  return 0;
}
/// The scalar recurrence of one coordinate under the coupling alone (b = b_a diagonal, r = k δt/b_a,
/// ρ = b_j/b_a): u_n = r x_n − ρ u_{n−1} (u = q̇ δt), x_{n+1} = x_n − u_n, from x_0 = 1, u_{−1} = 0.
/// Returns x_N and Σ_{n<N} u_n².
std::pair<double, double> couplingRecurrence(double r, double rho, int steps) {
  double x = 1, u = 0, sum_u2 = 0;
  for (int n = 0; n < steps; ++n) {
    u = r * x - rho * u;
    x -= u;
    sum_u2 += u * u;
  }
  return {x, sum_u2};
}
}  // namespace

TEST(Controller, JointCouplingTorqueIsTheSpringDamperOnTheManifoldAddedUnprojected) {
  // default config: 6 frames on two levels, projected posture control, gravity. The coupling's torque
  // is Γ_j = k∘(q_j ⊖ q) − b∘q̇_prev on every coordinate and enters q̇_free = b⁻¹(Γ_task + Γ_int + Γ_g + Γ_j)
  // as it is (no projection, no α).
  const auto& model = male50();
  ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  Controller ctl(model, c);
  const int nv = model.nv;
  const VectorX q0 = ctl.q();
  EXPECT_FALSE(ctl.jointCoupling());
  const int ball = firstJoint(model, skeleton::JointType::kBall);
  const int rev = firstJoint(model, skeleton::JointType::kRevolute);
  const int iq_b = model.joints[ball].idx_q, iv_b = model.joints[ball].idx_v;
  VectorX q_j = q0;
  q_j.head<3>() += Vector3(0.02, -0.01, 0.03);                                                 // root translation
  q_j.segment<3>(iq_b) = rotationVector(rotationOf(q0.segment<3>(iq_b)) * rotationOf(Vector3(0.2, -0.3, 0.25)));
  q_j(model.joints[rev].idx_q) += 0.15;
  VectorX k(nv), b(nv);
  for (int i = 0; i < nv; ++i) {
    k(i) = 20.0 + i;
    b(i) = 0.3 + 0.01 * i;
  }
  ctl.setJointCoupling(q_j, k, b);
  EXPECT_TRUE(ctl.jointCoupling());

  // step 1 from rest (q̇_prev = 0): Γ_j = k∘(q_j ⊖ q0); the ball's part is the rotation vector of
  // R(q0)ᵀ R(q_j) = the offset (0.2, −0.3, 0.25) put on it
  ASSERT_EQ(ctl.computeFreeMotion(), StepStatus::kOk);
  VectorX expected = k.cwiseProduct(skeleton::difference(model, q0, q_j));
  EXPECT_LT((ctl.jointCouplingTorque() - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ctl.jointCouplingTorque().segment<3>(iv_b) - k.segment<3>(iv_b).cwiseProduct(Vector3(0.2, -0.3, 0.25))).norm(), 1e-12);
  EXPECT_NEAR(ctl.jointCouplingTorque()(model.joints[rev].idx_v), 0.15 * k(model.joints[rev].idx_v), 1e-12);
  ctl.integrate();

  // step 2: the ball's difference by hand (Eigen's angle-axis), the damping on the last step's q̇
  const VectorX q1 = ctl.q(), v1 = ctl.qdot();
  ASSERT_GT(v1.cwiseAbs().maxCoeff(), 0.0);
  ASSERT_EQ(ctl.computeFreeMotion(), StepStatus::kOk);
  expected = k.cwiseProduct(skeleton::difference(model, q1, q_j)) - b.cwiseProduct(v1);
  const Vector3 e_ball = rotationVector(rotationOf(q1.segment<3>(iq_b)).transpose() * rotationOf(q_j.segment<3>(iq_b)));
  EXPECT_LT((expected.segment<3>(iv_b) -
             (k.segment<3>(iv_b).cwiseProduct(e_ball) - b.segment<3>(iv_b).cwiseProduct(v1.segment<3>(iv_b)))).norm(), 1e-12);
  const double scale = expected.cwiseAbs().maxCoeff();
  EXPECT_LT((ctl.jointCouplingTorque() - expected).cwiseAbs().maxCoeff(), 1e-12 * scale);
  // unprojected: b q̇_free = the plain sum
  const VectorX sum = ctl.taskTorque() + ctl.internalTorque() + ctl.gravityTorque() + ctl.jointCouplingTorque();
  const VectorX qdot_free = ctl.apparentFriction().ldlt().solve(sum);
  EXPECT_LT((ctl.qdotFree() - qdot_free).norm() / qdot_free.norm(), 1e-10);
  ctl.integrate();
  EXPECT_GT(std::abs(ctl.jointCouplingPort().energy), 0.0);
}

TEST(Controller, JointCouplingAloneConvergesToQjAndItsPortBalancesTheDissipation) {
  // The coupling alone (no frames, no gravity, no internal control): b = b_a and q̇ = b_a⁻¹Γ_j. With
  // k = r b_a/δt on every coordinate, q̇ δt is along (q_j ⊖ q) joint by joint, and q ⊕ q̇δt moves every
  // joint — revolute, ball (R exp(u)) and the free-flying root (H exp(V)) — along the one-parameter
  // subgroup towards q_j: e = q_j ⊖ q obeys the scalar recurrence of couplingRecurrence() exactly.
  // The port's power Γ_jᵀq̇ is q̇ᵀb_a q̇, the dissipation's, and its energy Σ b_a q̇² δt = (2U_0/r) Σ u_n²,
  // U_0 = ½ Σ k e_0²; without damping that is U_0 (1 − (1−r)^{2N}) / (1 − r/2): at most U_0/(1 − r/2), the
  // explicit step's overshoot of the stored energy.
  const auto& model = male50();
  ControllerConfig c = baseConfig();
  c.internal.enabled = false;
  const double r = 0.1;
  const int steps = 300;
  for (double rho : {0.0, 0.5}) {
    Controller ctl(model, c);
    const VectorX q0 = ctl.q();
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    VectorX offset(model.nv);
    for (int i = 0; i < model.nv; ++i) offset(i) = u(rng);
    const VectorX q_j = skeleton::integrate(model, q0, offset);
    const VectorX& b_a = ctl.frictionDiagonal();
    const VectorX k = (r / c.dt) * b_a, b = rho * b_a;
    ctl.setJointCoupling(q_j, k, b);
    const VectorX e0 = skeleton::difference(model, q0, q_j);
    const double U0 = 0.5 * e0.cwiseProduct(e0).dot(k);
    for (int n = 0; n < steps; ++n) ASSERT_EQ(ctl.step(), StepStatus::kOk);
    const auto [x_n, sum_u2] = couplingRecurrence(r, rho, steps);
    const VectorX e = skeleton::difference(model, ctl.q(), q_j);
    EXPECT_LT(std::abs(x_n), 1e-6) << "rho " << rho;  // the recurrence itself converges (|λ| < 1)
    EXPECT_LT((e - x_n * e0).cwiseAbs().maxCoeff(), 1e-9 * e0.cwiseAbs().maxCoeff()) << "rho " << rho;
    EXPECT_LT(e.cwiseAbs().maxCoeff(), 1e-6 * e0.cwiseAbs().maxCoeff()) << "q reaches q_j, rho " << rho;
    const double W = ctl.jointCouplingPort().energy;
    EXPECT_NEAR(W, ctl.dissipation().energy, 1e-9 * W) << "rho " << rho;
    EXPECT_NEAR(W, 2 * U0 / r * sum_u2, 1e-9 * W) << "rho " << rho;
    if (rho == 0) {
      EXPECT_NEAR(W, U0 * (1 - std::pow(1 - r, 2 * steps)) / (1 - r / 2), 1e-9 * W);
      EXPECT_LE(W, U0 / (1 - r / 2));
    }
    EXPECT_EQ(ctl.internalPort().energy, 0.0);
  }
}

TEST(Controller, JointCouplingBadInputIsRejectedNamedAndTheCouplingKept) {
  const auto& model = male50();
  ControllerConfig c = baseConfig();
  c.internal.enabled = false;
  Controller a(model, c), twin(model, c);
  const int nv = model.nv, nq = model.nq;
  const VectorX k = VectorX::Constant(nv, 30.0), b = VectorX::Constant(nv, 0.2);
  VectorX q_j = a.q();
  q_j.tail(nq - 6).array() += 0.1;
  // not set yet: a bad call leaves it off
  EXPECT_THROW(a.setJointCoupling(q_j, VectorX::Constant(nv, -1.0), b), std::invalid_argument);
  EXPECT_FALSE(a.jointCoupling());
  a.setJointCoupling(q_j, k, b);
  twin.setJointCoupling(q_j, k, b);
  const VectorX q_start = a.q();
  const auto expectRejected = [&](const VectorX& qq, const VectorX& kk, const VectorX& bb, const std::vector<std::string>& words) {
    try {
      a.setJointCoupling(qq, kk, bb);
      ADD_FAILURE() << "accepted; expected an error naming " << words.front();
    } catch (const std::invalid_argument& e) {
      for (const std::string& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
    }
    EXPECT_TRUE(a.jointCoupling());
  };
  expectRejected(q_j.head(nq - 1), k, b, {"sizes", std::to_string(nq - 1)});
  expectRejected(q_j, VectorX::Constant(nv + 1, 1.0), b, {"sizes", std::to_string(nv + 1)});
  expectRejected(q_j, k, VectorX(), {"sizes"});
  const auto names = model.coordinateNames();
  VectorX bad = q_j;
  bad(9) = std::nan("");
  expectRejected(bad, k, b, {"q_j(9", names[9], "not finite"});
  bad = k;
  bad(12) = std::numeric_limits<double>::infinity();
  expectRejected(q_j, bad, b, {"stiffness(12", names[12], "not finite"});
  bad = b;
  bad(3) = std::nan("");
  expectRejected(q_j, k, bad, {"damping(3", "not finite"});
  bad = k;
  bad(20) = -5;
  expectRejected(q_j, bad, b, {"stiffness(20", names[20], "negative"});
  bad = b;
  bad(nv - 1) = -1e-3;
  expectRejected(q_j, k, bad, {"damping(" + std::to_string(nv - 1), "negative"});
  // the coupling in place is the good one: same motion as the twin that never saw the bad calls
  for (int i = 0; i < 50; ++i) {
    ASSERT_EQ(a.step(), StepStatus::kOk);
    twin.step();
  }
  EXPECT_GT((a.q() - q_start).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((a.q() - twin.q()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((a.jointCouplingTorque() - twin.jointCouplingTorque()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(a.jointCouplingTorque().cwiseAbs().maxCoeff(), 0.0);
}

TEST(Controller, JointCouplingIsClearedByClearAndByReset) {
  // coupling alone (no frames, gravity or internal control): once cleared nothing moves the mannequin
  const auto& model = male50();
  ControllerConfig c = baseConfig();
  c.internal.enabled = false;
  Controller ctl(model, c);
  const VectorX q0 = ctl.q();
  VectorX q_j = q0;
  q_j.tail(model.nq - 6).array() += 0.1;
  const VectorX k = VectorX::Constant(model.nv, 30.0), b = VectorX::Constant(model.nv, 0.2);
  for (bool by_reset : {false, true}) {
    ctl.setJointCoupling(q_j, k, b);
    for (int i = 0; i < 20; ++i) ASSERT_EQ(ctl.step(), StepStatus::kOk);
    ASSERT_GT(ctl.jointCouplingTorque().cwiseAbs().maxCoeff(), 0.0);
    ASSERT_GT(ctl.jointCouplingPort().energy, 0.0);
    if (by_reset) {
      ctl.reset(q0);
      EXPECT_EQ(ctl.jointCouplingPort().energy, 0.0) << "reset() restarts the port like the others";
    } else {
      ctl.clearJointCoupling();
    }
    EXPECT_FALSE(ctl.jointCoupling());
    EXPECT_EQ(ctl.jointCouplingTorque().cwiseAbs().maxCoeff(), 0.0);
    const VectorX before = ctl.q();
    const double port = ctl.jointCouplingPort().energy;
    for (int i = 0; i < 20; ++i) ASSERT_EQ(ctl.step(), StepStatus::kOk);
    EXPECT_EQ(ctl.jointCouplingTorque().cwiseAbs().maxCoeff(), 0.0) << (by_reset ? "reset" : "clear");
    EXPECT_EQ(ctl.jointCouplingPort().energy, port);
    // no torque at all: q̇ = 0 (the last q̇ only enters through the coupling's damping); q ⊕ 0 = q to
    // rounding (the root's rotation goes through exp/log)
    EXPECT_EQ(ctl.qdot().cwiseAbs().maxCoeff(), 0.0) << (by_reset ? "reset" : "clear");
    EXPECT_LT((ctl.q() - before).cwiseAbs().maxCoeff(), 1e-15) << (by_reset ? "reset" : "clear");
  }
}
