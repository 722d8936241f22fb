#include "mannequin/kinetics/motion.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::kinetics {

namespace {
// two passes of a second-order Butterworth: each pass's cutoff raised by 1/0.802 (Winter §3.4.4.2)
constexpr double kTwoPassCorrection = 0.802;
}  // namespace

ZeroLagLowPass::ZeroLagLowPass(double cutoff_hz, double rate_hz) : cutoff_hz_(cutoff_hz) {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz))
    throw std::invalid_argument("low-pass filter: sampling rate " + std::to_string(rate_hz) + " Hz must be > 0");
  const double pass_cutoff = cutoff_hz / kTwoPassCorrection;
  if (!(cutoff_hz > 0) || !(pass_cutoff < 0.5 * rate_hz))
    throw std::invalid_argument("low-pass filter: cutoff " + std::to_string(cutoff_hz) + " Hz must be in (0, " +
                                std::to_string(0.5 * rate_hz * kTwoPassCorrection) + ") Hz at " +
                                std::to_string(rate_hz) + " Hz sampling");
  // bilinear transform of H(s) = 1 / (s² + √2 s + 1) with the prewarped cutoff
  const double K = std::tan(std::numbers::pi * pass_cutoff / rate_hz);
  const double norm = 1.0 + std::sqrt(2.0) * K + K * K;
  b0_ = K * K / norm;
  b1_ = 2.0 * b0_;
  b2_ = b0_;
  a1_ = 2.0 * (K * K - 1.0) / norm;
  a2_ = (1.0 - std::sqrt(2.0) * K + K * K) / norm;
}

void ZeroLagLowPass::apply(std::vector<double>& x) const {
  if (x.empty()) return;
  const auto pass = [&](auto begin, auto end) {
    // state at steady state on the first sample (unit DC gain)
    double x1 = *begin, x2 = *begin, y1 = *begin, y2 = *begin;
    for (auto it = begin; it != end; ++it) {
      const double xin = *it;
      const double y = b0_ * xin + b1_ * x1 + b2_ * x2 - a1_ * y1 - a2_ * y2;
      x2 = x1;
      x1 = xin;
      y2 = y1;
      y1 = y;
      *it = y;
    }
  };
  pass(x.begin(), x.end());
  pass(x.rbegin(), x.rend());
}

MotionDerivatives differentiate(const skeleton::Model& model, const std::vector<VectorX>& q, double dt,
                                const DifferentiationOptions& options) {
  const std::size_t n = q.size();
  if (n < 3) throw std::invalid_argument("differentiate: " + std::to_string(n) + " samples, need at least 3");
  if (!(dt > 0) || !std::isfinite(dt)) throw std::invalid_argument("differentiate: time step " + std::to_string(dt) + " s must be > 0");
  for (std::size_t k = 0; k < n; ++k) {
    if (q[k].size() != model.nq)
      throw std::invalid_argument("differentiate: sample " + std::to_string(k) + " has " + std::to_string(q[k].size()) +
                                  " coordinates, the model has " + std::to_string(model.nq));
    if (!q[k].allFinite()) throw std::invalid_argument("differentiate: sample " + std::to_string(k) + " is not finite");
  }
  MotionDerivatives out;
  out.v.resize(n);
  out.a.resize(n);
  out.v[0] = skeleton::difference(model, q[0], q[1]) / dt;
  out.v[n - 1] = skeleton::difference(model, q[n - 2], q[n - 1]) / dt;
  for (std::size_t k = 1; k + 1 < n; ++k) out.v[k] = skeleton::difference(model, q[k - 1], q[k + 1]) / (2 * dt);
  if (options.cutoff_hz > 0) {
    const ZeroLagLowPass filter(options.cutoff_hz, 1.0 / dt);
    std::vector<double> signal(n);
    for (int c = 0; c < model.nv; ++c) {
      for (std::size_t k = 0; k < n; ++k) signal[k] = out.v[k](c);
      filter.apply(signal);
      for (std::size_t k = 0; k < n; ++k) out.v[k](c) = signal[k];
    }
  }
  out.a[0] = (out.v[1] - out.v[0]) / dt;
  out.a[n - 1] = (out.v[n - 1] - out.v[n - 2]) / dt;
  for (std::size_t k = 1; k + 1 < n; ++k) out.a[k] = (out.v[k + 1] - out.v[k - 1]) / (2 * dt);
  return out;
}

}  // namespace mannequin::kinetics
