// The zero-lag low-pass filter against the Butterworth response it is designed to have, and the
// differentiation of a sampled motion against analytic derivatives.
#include "mannequin/kinetics/motion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace mannequin;
using namespace mannequin::kinetics;

namespace {

// amplitude of a unit sine of frequency f after the filter, measured on the middle half of 20 s
double gain(const ZeroLagLowPass& filter, double f, double rate) {
  const int n = static_cast<int>(20 * rate);
  std::vector<double> x(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) x[static_cast<std::size_t>(k)] = std::sin(2 * std::numbers::pi * f * k / rate);
  filter.apply(x);
  double peak = 0;
  for (int k = n / 4; k < 3 * n / 4; ++k) peak = std::max(peak, std::abs(x[static_cast<std::size_t>(k)]));
  return peak;
}

skeleton::Model hinge() {
  skeleton::Model m;
  m.addJoint("hinge", skeleton::JointType::kRevolute, -1, math::SE3::Identity(), math::Vector3::UnitX());
  return m;
}
}  // namespace

TEST(ZeroLagLowPass, HasTheFourthOrderButterworthResponse) {
  // two passes of a second-order Butterworth: |H(f)|² = 1 / (1 + (f/fc)⁴) per pass, so |H|² overall is
  // 1/(1 + (f/fc')⁴)² with fc' = fc/0.802 making the pair −3 dB (gain 1/√2) at fc
  const double rate = 200, fc = 6;
  const ZeroLagLowPass filter(fc, rate);
  EXPECT_NEAR(gain(filter, fc, rate), 1 / std::sqrt(2.0), 0.02);
  EXPECT_NEAR(gain(filter, 0.1 * fc, rate), 1.0, 0.01);
  EXPECT_LT(gain(filter, 10 * fc, rate), 0.01);
  // a constant passes unchanged, ends included (steady-state start)
  std::vector<double> x(50, 3.5);
  filter.apply(x);
  for (double y : x) EXPECT_NEAR(y, 3.5, 1e-12);
}

TEST(ZeroLagLowPass, HasNoPhaseLag) {
  // the peak of a filtered 1 Hz sine stays where it was (a one-way filter would delay it by tens of ms)
  const double rate = 1000;
  const ZeroLagLowPass filter(6, rate);
  std::vector<double> x(4000);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = std::sin(2 * std::numbers::pi * static_cast<double>(k) / rate);
  filter.apply(x);
  // 2.25 s: a peak of sin(2π t)
  std::size_t best = 2000;
  for (std::size_t k = 2000; k < 2500; ++k)
    if (x[k] > x[best]) best = k;
  EXPECT_NEAR(static_cast<double>(best), 2250.0, 1.0);
}

TEST(ZeroLagLowPass, RefusesACutoffAboveNyquist) {
  EXPECT_THROW(ZeroLagLowPass(90, 200), std::invalid_argument);
  EXPECT_THROW(ZeroLagLowPass(0, 200), std::invalid_argument);
  EXPECT_THROW(ZeroLagLowPass(6, -1), std::invalid_argument);
  EXPECT_THROW(ZeroLagLowPass(std::nan(""), 100), std::invalid_argument);
}

TEST(Differentiate, SineMatchesItsAnalyticDerivatives) {
  // θ = 0.5 sin(2π t) at 1 kHz: θ̇ = π cos(2π t), θ̈ = −2π² sin(2π t); the 6 Hz filter passes 1 Hz with a
  // gain of 1/√(1 + (1/7.48)⁸)² ≈ 1 − 1e-7
  const skeleton::Model m = hinge();
  const double dt = 1e-3;
  std::vector<VectorX> q;
  for (int k = 0; k <= 3000; ++k) q.push_back(VectorX::Constant(1, 0.5 * std::sin(2 * std::numbers::pi * k * dt)));
  const MotionDerivatives d = differentiate(m, q, dt);
  ASSERT_EQ(d.v.size(), q.size());
  for (int k = 500; k <= 2500; k += 125) {
    const double t = k * dt;
    EXPECT_NEAR(d.v[static_cast<std::size_t>(k)](0), std::numbers::pi * std::cos(2 * std::numbers::pi * t), 1e-3 * std::numbers::pi) << t;
    EXPECT_NEAR(d.a[static_cast<std::size_t>(k)](0), -2 * std::numbers::pi * std::numbers::pi * std::sin(2 * std::numbers::pi * t), 1e-2 * 2 * std::numbers::pi * std::numbers::pi) << t;
  }
}

TEST(Differentiate, NoiseIsFilteredOutOfTheAcceleration) {
  // 0.2 mrad of 100 Hz tremor on a still joint: differentiated twice it is 2e-4 (2π 100)² ≈ 79 rad/s²;
  // the 6 Hz fourth-order filter passes (1 + (100/7.48)⁴)⁻¹ ≈ 3e-5 of it
  const skeleton::Model m = hinge();
  const double dt = 1e-3;
  std::vector<VectorX> q;
  for (int k = 0; k <= 2000; ++k) q.push_back(VectorX::Constant(1, 0.3 + 2e-4 * std::sin(2 * std::numbers::pi * 100 * k * dt)));
  const MotionDerivatives raw = differentiate(m, q, dt, DifferentiationOptions{0.0});
  const MotionDerivatives filtered = differentiate(m, q, dt);
  double raw_peak = 0, filtered_peak = 0;
  for (std::size_t k = 500; k < 1500; ++k) {  // past the filter's transients at the ends (≈ 1/fc)
    raw_peak = std::max(raw_peak, std::abs(raw.a[k](0)));
    filtered_peak = std::max(filtered_peak, std::abs(filtered.a[k](0)));
  }
  EXPECT_GT(raw_peak, 50.0);
  EXPECT_LT(filtered_peak, 1e-3 * raw_peak);
}

TEST(Differentiate, MeanAccelerationOfARestToRestMotionIsZero) {
  // Σ a_k telescopes: a motion starting and ending at rest has zero mean acceleration
  const skeleton::Model m = hinge();
  const double dt = 1e-3;
  std::vector<VectorX> q;
  for (int k = 0; k <= 2000; ++k) {
    const double t = k * dt;
    const double s = t < 0.5 ? 0 : t > 1.5 ? 1 : 0.5 * (1 - std::cos(std::numbers::pi * (t - 0.5)));
    q.push_back(VectorX::Constant(1, 1.2 * s));
  }
  const MotionDerivatives d = differentiate(m, q, dt);
  double sum = 0, peak = 0;
  for (const VectorX& a : d.a) {
    sum += a(0);
    peak = std::max(peak, std::abs(a(0)));
  }
  EXPECT_GT(peak, 5.0);  // 1.2 π²/2 ≈ 5.9 rad/s² at the ends of the move
  EXPECT_LT(std::abs(sum / static_cast<double>(d.a.size())), 1e-6 * peak);
}

TEST(Differentiate, RefusesBadInput) {
  const skeleton::Model m = hinge();
  const std::vector<VectorX> two(2, VectorX::Zero(1));
  EXPECT_THROW(differentiate(m, two, 1e-3), std::invalid_argument);
  std::vector<VectorX> q(5, VectorX::Zero(1));
  EXPECT_THROW(differentiate(m, q, 0.0), std::invalid_argument);
  q[3](0) = std::nan("");
  EXPECT_THROW(differentiate(m, q, 1e-3), std::invalid_argument);
  q[3] = VectorX::Zero(2);
  EXPECT_THROW(differentiate(m, q, 1e-3), std::invalid_argument);
}
