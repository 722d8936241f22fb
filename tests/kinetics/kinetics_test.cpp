// Whole-body kinetics on the 50th-percentile male: quiet standing, a held box, a rest-to-rest bob and a
// free fall, each checked against the physics it must obey (momentum balance), not a recorded figure.
#include "mannequin/kinetics/kinetics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../common/mannequins.hpp"
#include "mannequin/kinetics/motion.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin;
using namespace mannequin::kinetics;

namespace {
constexpr double kG = 9.81;

// four corners of each sole (±10 cm along the foot, ±4 cm across) on the floor z = 0
std::vector<ContactPoint> feetOnTheFloor(const skeleton::Model& m, const VectorX& q) {
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, q);
  std::vector<ContactPoint> out;
  for (const char* sole : {"sole_l", "sole_r"}) {
    const int f = m.frameIndex(sole);
    for (double x : {-0.1, 0.1})
      for (double y : {-0.04, 0.04}) {
        ContactPoint c;
        c.point = d.oMf[static_cast<std::size_t>(f)].act(Vector3(x, y, 0));
        c.normal = Vector3::UnitZ();
        c.mu = 0.6;
        c.joint = m.frames[static_cast<std::size_t>(f)].joint;
        out.push_back(c);
      }
  }
  return out;
}

int rootZ(const skeleton::Model& m) { return m.joints[0].idx_q + 2; }
}  // namespace

TEST(Kinetics, QuietStandingGroundReactionIsTheWeight) {
  const skeleton::Model& m = mannequin::testing::male50();
  const double weight = m.totalMass() * kG;
  const VectorX q = skeleton::standingConfiguration(m);
  KineticsSolver solver(m);
  const KineticsFrame f = solver.solve(q, VectorX::Zero(m.nv), VectorX::Zero(m.nv), feetOnTheFloor(m, q));
  ASSERT_EQ(f.status, lcp::LcpStatus::Solved);
  EXPECT_NEAR(f.contact_force.z(), weight, 0.02 * weight);
  EXPECT_LT(f.residual_force.norm(), 0.01 * weight);
  EXPECT_LT(f.residual_moment.norm(), 0.01 * weight * f.com.z());
  // the root is held by the contacts, not by an outside hand: its generalised force is the residual
  EXPECT_LT(f.tau.head<6>().norm(), 0.01 * weight * f.com.z());
}

TEST(Kinetics, HoldingABoxAddsItsWeightToTheGroundReaction) {
  const skeleton::Model& m = mannequin::testing::male50();
  const double weight = m.totalMass() * kG, box = 10.0 * kG;
  const VectorX q = skeleton::standingConfiguration(m);
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, q);
  std::vector<Load> loads;
  for (const char* palm : {"palm_l", "palm_r"}) {
    const auto f = static_cast<std::size_t>(m.frameIndex(palm));
    loads.push_back(Load{m.frames[f].joint, d.oMf[f].p, Vector3(0, 0, -box / 2)});
  }
  KineticsSolver solver(m);
  const KineticsFrame f = solver.solve(q, VectorX::Zero(m.nv), VectorX::Zero(m.nv), feetOnTheFloor(m, q), loads);
  EXPECT_NEAR(f.contact_force.z(), weight + box, 0.02 * (weight + box));
  EXPECT_LT(f.residual_force.norm(), 0.01 * weight);
}

TEST(Kinetics, RestToRestBobAveragesTheWeightAndFollowsTheAcceleration) {
  // the whole body rises 10 cm and comes down in 1 s (z = A(1 − cos ωt)/2, ω = 2π), after and before 0.3 s
  // at rest: the floor gives m(g + z̈) at every instant, m g on average
  const skeleton::Model& m = mannequin::testing::male50();
  // sampled at 250 Hz (central differences of the cosine within (ω dt)²/12 ≈ 5e-5), cones of 4 edges: the
  // 400 solves stay quick under the sanitizers
  const double mass = m.totalMass(), weight = mass * kG, A = 0.10, w = 2 * std::numbers::pi, dt = 4e-3;
  const VectorX q0 = skeleton::standingConfiguration(m);
  std::vector<VectorX> q;
  for (int k = 0; k <= 400; ++k) {
    const double t = k * dt - 0.3;
    VectorX qk = q0;
    if (t > 0 && t < 1) qk(rootZ(m)) += A * (1 - std::cos(w * t)) / 2;
    q.push_back(qk);
  }
  const MotionDerivatives md = differentiate(m, q, dt, DifferentiationOptions{0.0});
  KineticsOptions options;
  options.distribution.edges = 4;
  KineticsSolver solver(m, options);
  std::vector<KineticsFrame> frames;
  for (std::size_t k = 0; k < q.size(); ++k)
    frames.push_back(solver.solve(q[k], md.v[k], md.a[k], feetOnTheFloor(m, q[k])));
  const KineticsSummary s = summarize(frames, weight);
  EXPECT_NEAR(s.grf_mean_over_weight, 1.0, 0.03);
  EXPECT_LT(s.residual_force_mean_n, 0.01 * weight);
  for (double t : {0.1, 0.25, 0.5, 0.8}) {
    const auto k = static_cast<std::size_t>(std::lround((t + 0.3) / dt));
    const double zdd = A * w * w / 2 * std::cos(w * t);
    EXPECT_NEAR(frames[k].contact_force.z(), mass * (kG + zdd), 0.01 * weight) << "t = " << t;
  }
  EXPECT_GT(s.peak_external_force_n, weight + 0.9 * mass * A * w * w / 2);
}

TEST(Kinetics, AFreeFallNeedsNoForceAndLeavesNoResidual) {
  // dropped from rest, no contact: the motion needs no external wrench, so the residual is zero
  const skeleton::Model& m = mannequin::testing::male50();
  const double dt = 1e-3;
  const VectorX q0 = skeleton::standingConfiguration(m);
  std::vector<VectorX> q;
  for (int k = 0; k <= 300; ++k) {
    VectorX qk = q0;
    qk(rootZ(m)) += 2.0 - 0.5 * kG * (k * dt) * (k * dt);
    q.push_back(qk);
  }
  const MotionDerivatives md = differentiate(m, q, dt, DifferentiationOptions{0.0});
  KineticsSolver solver(m);
  for (std::size_t k = 2; k + 2 < q.size(); k += 49) {  // central differences of central differences
    const KineticsFrame f = solver.solve(q[k], md.v[k], md.a[k], {});
    EXPECT_LT(f.residual_force.norm(), 1e-6 * m.totalMass() * kG) << k;
    EXPECT_LT(f.contact_force.norm(), 1e-12);
  }
  // held still in the air, the whole weight is residual: the "hand of god" is reported, not hidden
  const KineticsFrame held = solver.solve(q[100], VectorX::Zero(m.nv), VectorX::Zero(m.nv), {});
  EXPECT_NEAR(held.residual_force.z(), m.totalMass() * kG, 1e-6);
}

TEST(Kinetics, RefusesBadInputNamingIt) {
  const skeleton::Model& m = mannequin::testing::male50();
  KineticsSolver solver(m);
  const VectorX q = skeleton::standingConfiguration(m);
  const VectorX z = VectorX::Zero(m.nv);
  EXPECT_THROW(solver.solve(q.head(3), z, z, {}), std::invalid_argument);
  VectorX bad = z;
  bad(4) = std::nan("");
  EXPECT_THROW(solver.solve(q, bad, z, {}), std::invalid_argument);
  try {
    solver.solve(q, z, z, {}, {Load{999, Vector3::Zero(), Vector3::Zero()}});
    FAIL() << "a load on joint 999 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("load 0"), std::string::npos) << e.what();
  }
  EXPECT_THROW(summarize({}, 0.0), std::invalid_argument);
}
