// Swing/twist decomposition of a ball joint (thesis Annex D.2): R = R_s R_t round trip, finite-difference
// checks of ds/dω, dθ_t/dω, dθ_s/dω and of the limit rows (swing ellipse and twist range) at random
// configurations, near swing 0, near the limits and near the singularity at π.
#include <gtest/gtest.h>

#include <random>
#include <type_traits>

#include "mannequin/constraints/swing_twist.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

using namespace mannequin;
using namespace mannequin::constraints;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {
constexpr double kPi = 3.14159265358979323846;

Vector3d randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  return Vector3d(n(rng), n(rng), n(rng)).normalized();
}

/// A rotation with swing angle `swing` (about a random axis ⟂ t) and twist `twist` about t.
Matrix3d rotation(const Vector3d& t, double swing, double twist, std::mt19937& rng) {
  Vector3d u = randomUnit(rng);
  u = (u - u.dot(t) * t).normalized();
  return math::expSO3(swing * u) * math::expSO3(twist * t);
}

/// Central difference of f along ω (body): (f(R exp(hω)) − f(R exp(−hω)))/2h.
template <class F>
auto fd(const Matrix3d& R, const Vector3d& w, F f, double h = 1e-6) {
  using T = std::decay_t<decltype(f(R))>;
  return T((f(R * math::expSO3(h * w)) - f(R * math::expSO3(-h * w))) / (2 * h));
}

skeleton::BallLimit shoulderLike() {
  skeleton::BallLimit l;
  l.enabled = true;
  l.twist_axis = -Vector3d::UnitZ();
  l.swing_x = Vector3d::UnitX();
  l.swing_y = Vector3d::UnitY();
  l.swing_a = 1.2;
  l.swing_b = 0.8;
  l.swing_cx = 0.4;
  l.swing_cy = -0.3;
  l.twist_lower = -1.0;
  l.twist_upper = 0.7;
  return l;
}
}  // namespace

TEST(SwingTwist, DecompositionRoundTrip) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> sw(0.0, 3.0), tw(-3.0, 3.0);
  for (int i = 0; i < 200; ++i) {
    const Vector3d t = randomUnit(rng);
    const double s0 = i < 10 ? 1e-7 * i : sw(rng), t0 = tw(rng);
    const Matrix3d R = rotation(t, s0, t0, rng);
    const SwingTwist st = swingTwist(R, t);
    EXPECT_NEAR(st.swing_angle, s0, 1e-9);
    EXPECT_NEAR(st.swing.norm(), s0, 1e-9);
    EXPECT_NEAR(st.swing.dot(t), 0.0, 1e-12);  // s ⟂ t
    EXPECT_NEAR(st.twist, t0, 1e-8);
    // R_s takes t to R t (the geodesic swing), and R = R_s R_t
    EXPECT_LT((swingRotation(st) * t - R * t).norm(), 1e-12);
    EXPECT_LT((swingRotation(st) * twistRotation(st, t) - R).norm(), 1e-9);
  }
}

TEST(SwingTwist, ByHandSwingAboutXThenTwist) {
  // t = −z; swing 0.5 rad about x (s = 0.5 x) then twist 0.3 rad about −z
  const Vector3d t = -Vector3d::UnitZ();
  const Matrix3d R = math::expSO3(Vector3d(0.5, 0, 0)) * math::expSO3(0.3 * t);
  const SwingTwist st = swingTwist(R, t);
  EXPECT_LT((st.swing - Vector3d(0.5, 0, 0)).norm(), 1e-12);
  EXPECT_NEAR(st.twist, 0.3, 1e-12);
  // a pure rotation about t is all twist
  const SwingTwist pure = swingTwist(math::expSO3(Vector3d(0, 0, 0.9)), t);
  EXPECT_LT(pure.swing.norm(), 1e-12);
  EXPECT_NEAR(pure.twist, -0.9, 1e-12);
}

TEST(SwingTwist, JacobiansMatchFiniteDifferences) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> tw(-2.5, 2.5);
  // swing angles: random, near 0 (series branch, both sides of its 1e-3 switch), up to 170°
  const double swings[] = {1e-6, 5e-4, 2e-3, 0.1, 0.7, 1.5, 2.2, 2.8, 170 * kPi / 180};
  double worst_s = 0, worst_t = 0, worst_a = 0;
  for (double s0 : swings)
    for (int i = 0; i < 20; ++i) {
      const Vector3d t = randomUnit(rng);
      const Matrix3d R = rotation(t, s0, tw(rng), rng);
      const SwingTwist st = swingTwist(R, t);
      ASSERT_FALSE(st.singular);
      const Vector3d w = randomUnit(rng);
      const Vector3d ds = fd(R, w, [&](const Matrix3d& Q) { return swingTwist(Q, t).swing; });
      const double dt = fd(R, w, [&](const Matrix3d& Q) { return swingTwist(Q, t).twist; });
      const double scale = 1.0 / std::sin(std::max(s0, 0.5));  // |ds/dω| grows as θ/sin θ
      worst_s = std::max(worst_s, (ds - st.swing_jacobian * w).norm() / scale);
      worst_t = std::max(worst_t, std::abs(dt - st.twist_jacobian * w) / scale);
      if (s0 > 1e-3) {  // θ_s is a cone at 0: no derivative there
        const double da = fd(R, w, [&](const Matrix3d& Q) { return swingTwist(Q, t).swing_angle; });
        worst_a = std::max(worst_a, std::abs(da - st.swing_angle_jacobian * w));
      }
    }
  EXPECT_LT(worst_s, 1e-7);
  EXPECT_LT(worst_t, 1e-7);
  EXPECT_LT(worst_a, 1e-7);
}

TEST(SwingTwist, SmoothAtZeroSwing) {
  // at s = 0 exactly ds/dω = −[t]R[t] (70's matrix, R = R_t) and dθ_t/dω = tᵀ: a pure twist about t
  // changes θ_t at rate 1 and the swing not at all, a rotation ⟂ t moves s at rate 1
  const Vector3d t = -Vector3d::UnitZ();
  const Matrix3d R = math::expSO3(0.4 * t);
  const SwingTwist st = swingTwist(R, t);
  EXPECT_LT((st.swing_jacobian - (-math::hat(t) * R * math::hat(t))).norm(), 1e-12);
  EXPECT_LT((st.twist_jacobian - t.transpose()).norm(), 1e-12);
  EXPECT_LT((st.swing_jacobian * t).norm(), 1e-12);
  EXPECT_NEAR((st.swing_jacobian * Vector3d::UnitX()).norm(), 1.0, 1e-12);
}

TEST(SwingTwist, NearPiTheDecompositionIsSingularAndFlagged) {
  const Vector3d t = -Vector3d::UnitZ();
  std::mt19937 rng(3);
  // the swing Jacobian grows like θ/sin θ as θ_s → π: measured at 170°, 174°
  const double n170 = swingTwist(rotation(t, 170 * kPi / 180, 0.2, rng), t).swing_jacobian.norm();
  const double n174 = swingTwist(rotation(t, 174 * kPi / 180, 0.2, rng), t).swing_jacobian.norm();
  EXPECT_GT(n174, 1.5 * n170);
  // past 175°: flagged, no swing/twist Jacobians, the swing angle's Jacobian is still right
  for (double s0 : {176 * kPi / 180, 179.9 * kPi / 180}) {
    const Matrix3d R = rotation(t, s0, 0.3, rng);
    const SwingTwist st = swingTwist(R, t);
    EXPECT_TRUE(st.singular);
    EXPECT_EQ(st.swing_jacobian.norm(), 0.0);
    EXPECT_EQ(st.twist_jacobian.norm(), 0.0);
    const Vector3d w = randomUnit(rng);
    const double h = 1e-7;
    const double da = fd(R, w, [&](const Matrix3d& Q) { return swingTwist(Q, t).swing_angle; }, h);
    EXPECT_NEAR(da, st.swing_angle_jacobian * w, 1e-6);
  }
  // exactly π: the swing direction is the fallback's part ⟂ t, s = π u
  const SwingTwist pi = swingTwist(math::expSO3(Vector3d(kPi, 0, 0)), t, Vector3d::UnitY());
  EXPECT_TRUE(pi.singular);
  EXPECT_NEAR(pi.swing_angle, kPi, 1e-12);
  EXPECT_TRUE(pi.swing.allFinite());
  EXPECT_NEAR(pi.swing.norm(), kPi, 1e-12);
  EXPECT_NEAR(pi.swing_angle_jacobian.norm(), 1.0, 1e-9);  // θ_s is 1-Lipschitz: a unit rate
}

TEST(SwingTwist, EllipseByHand) {
  skeleton::BallLimit l = shoulderLike();
  // along +x from the centre (0.4, −0.3): the ray from 0 along x meets the ellipse at
  // ((ρ − 0.4)/1.2)² + (0.3/0.8)² = 1 → ρ = 0.4 + 1.2·sqrt(1 − 0.140625)
  const double rho = 0.4 + 1.2 * std::sqrt(1 - 0.140625);
  EXPECT_NEAR(ellipseRadius(l, Vector3d::UnitX()), rho, 1e-12);
  EXPECT_NEAR(ellipseLevel(l, rho * Vector3d::UnitX()), 1.0, 1e-12);
  // the row's distance is the radial distance to first order near the boundary (rad)
  const Vector3d t = l.twist_axis;
  for (double eps : {1e-3, -1e-3, 1e-2}) {
    const Matrix3d R = math::expSO3((rho - eps) * Vector3d::UnitX());
    const BallLimitDistances d = ballLimitDistances(l, R);
    EXPECT_NEAR(d.swing, eps, 2 * eps * eps / rho + 1e-12) << eps;
    EXPECT_NEAR(d.swing_excess, std::max(0.0, -eps), 1e-12);
  }
  // centred circle of radius r: d = (r/2)(1 − |s|²/r²) exactly (κ = r/2)
  l.swing_cx = l.swing_cy = 0;
  l.swing_a = l.swing_b = 0.9;
  const BallLimitDistances c = ballLimitDistances(l, math::expSO3(Vector3d(0.3, 0.4, 0)));
  EXPECT_NEAR(c.swing_scale, 0.45, 1e-12);
  EXPECT_NEAR(c.swing, 0.45 * (1 - 0.25 / 0.81), 1e-12);
  (void)t;
}

TEST(SwingTwist, LimitRowsMatchFiniteDifferencesNearTheLimits) {
  // d(R exp(δt ω)) − d(R) ≈ δt J ω for the swing row (κ frozen) and the twist rows, at configurations
  // on, inside and outside the ellipse and the twist range
  const skeleton::BallLimit l = shoulderLike();
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> frac(0.9, 1.1), tw(-1.1, 0.8);
  double worst = 0;
  for (int i = 0; i < 200; ++i) {
    Vector3d u = randomUnit(rng);
    u = (u - u.dot(l.twist_axis) * l.twist_axis).normalized();
    const double rho = ellipseRadius(l, u);
    const Matrix3d R = math::expSO3(frac(rng) * rho * u) * math::expSO3(tw(rng) * l.twist_axis);
    const BallLimitDistances d = ballLimitDistances(l, R);
    ASSERT_FALSE(d.singular);
    const Vector3d w = randomUnit(rng);
    const double kappa = d.swing_scale;
    const double ds = fd(R, w, [&](const Matrix3d& Q) {
      return kappa * (1 - ellipseLevel(l, swingTwist(Q, l.twist_axis).swing));
    });
    const double dlo = fd(R, w, [&](const Matrix3d& Q) { return ballLimitDistances(l, Q).twist_lower; });
    const double dhi = fd(R, w, [&](const Matrix3d& Q) { return ballLimitDistances(l, Q).twist_upper; });
    worst = std::max({worst, std::abs(ds - d.swing_jacobian * w), std::abs(dlo - d.twist_jacobian * w),
                      std::abs(dhi + d.twist_jacobian * w)});
  }
  EXPECT_LT(worst, 1e-7);
}

TEST(SwingTwist, MannequinBallJointsHaveUsableDefaults) {
  for (const char* file : {"configs/mannequins/male_50th.yaml", "configs/mannequins/female_05th.yaml",
                           "configs/mannequins/male_95th.yaml"}) {
    const skeleton::Model m = skeleton::buildMannequin(skeleton::loadMannequinSpec(file));
    const skeleton::VectorX q0 = skeleton::standingConfiguration(m);
    for (const skeleton::Joint& j : m.joints) {
      if (j.type != skeleton::JointType::kBall) continue;
      ASSERT_TRUE(j.ball_limit.enabled) << j.name;
      EXPECT_EQ(skeleton::checkBallLimit(j.ball_limit), "") << j.name;
      // the standing posture is inside every swing/twist limit
      const BallLimitDistances d = ballLimitDistances(j.ball_limit, math::expSO3(q0.segment<3>(j.idx_q)));
      EXPECT_GT(d.swing, 0.0) << file << " " << j.name;
      EXPECT_GT(d.twist_lower, 0.0) << j.name;
      EXPECT_GT(d.twist_upper, 0.0) << j.name;
    }
  }
}

TEST(SwingTwist, ValuesWithoutJacobiansAreTheSameNumbers) {
  // the refinement's look-ahead and the World's diagnostics ask for distances only: the same values, bit
  // for bit, at random rotations (the singular band included), and no Jacobian
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> sw(0.0, kPi), tw(-3.0, 3.0);
  const skeleton::BallLimit l = shoulderLike();
  int singular = 0;
  for (int i = 0; i < 300; ++i) {
    const double s0 = i < 20 ? kPi - 1e-3 * i : sw(rng);
    const Matrix3d R = rotation(l.twist_axis, s0, tw(rng), rng);
    const BallLimitDistances full = ballLimitDistances(l, R), values = ballLimitDistances(l, R, false);
    singular += full.singular ? 1 : 0;
    EXPECT_EQ(values.singular, full.singular);
    EXPECT_EQ(values.swing, full.swing);
    EXPECT_EQ(values.swing_scale, full.swing_scale);
    EXPECT_EQ(values.swing_excess, full.swing_excess);
    EXPECT_EQ(values.twist_lower, full.twist_lower);
    EXPECT_EQ(values.twist_upper, full.twist_upper);
    EXPECT_EQ(values.st.swing_angle, full.st.swing_angle);
    EXPECT_EQ(values.st.twist, full.st.twist);
    EXPECT_EQ(values.st.swing, full.st.swing);
    EXPECT_EQ(values.st.swing_dir, full.st.swing_dir);
    EXPECT_EQ(values.swing_jacobian.squaredNorm(), 0.0);
    EXPECT_EQ(values.twist_jacobian.squaredNorm(), 0.0);
    EXPECT_EQ(values.st.swing_jacobian.squaredNorm(), 0.0);
    if (!full.singular) {
      EXPECT_GT(full.swing_jacobian.squaredNorm(), 0.0);
    }
  }
  EXPECT_GT(singular, 0);  // the band near π was visited
}
