#pragma once
/// \file motion.hpp
/// \brief Velocities and accelerations of a sampled motion, and the low-pass filter they use.
///
/// Biomechanics differentiates measured positions after a zero-lag low-pass filter (Winter,
/// "Biomechanics and Motor Control of Human Movement", 4th ed., §3.4): double differentiation
/// multiplies the noise at frequency f by (2πf)², so the capture's tremor and marker jitter would
/// otherwise dominate the accelerations, hence the forces. Here:
/// 1. v_k = difference(q_{k−1}, q_{k+1}) / 2Δt (central, on the configuration manifold: ball and
///    free-flyer velocities are body-frame, as everywhere in the model; one-sided at the ends);
/// 2. v is low-pass filtered by a second-order Butterworth run forward then backward (fourth order,
///    zero phase lag; the cutoff corrected by 1/0.802 so that the two passes together are −3 dB at
///    the cutoff asked for, Winter §3.4.4.2);
/// 3. a_k = (v_{k+1} − v_{k−1}) / 2Δt of the filtered v (one-sided at the ends).
/// Step 3 telescopes: Σ a_k Δt = (v_last + v_{last−1} − v_1 − v_0)/2, so over a motion that starts and
/// ends at rest the mean acceleration is zero and the mean external force is exactly the weight.
#include <vector>

#include "mannequin/math/types.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::kinetics {

using math::VectorX;

/// A second-order low-pass Butterworth filter (bilinear transform), run forward then backward.
class ZeroLagLowPass {
 public:
  /// \param cutoff_hz the −3 dB frequency of the forward–backward pair (Hz, 0 < cutoff < rate/2 · 0.8)
  /// \param rate_hz the sampling rate (Hz). \throws std::invalid_argument naming the bad value.
  ZeroLagLowPass(double cutoff_hz, double rate_hz);
  /// Filters one signal in place (a steady state at the first and last samples: no start-up transient
  /// for a signal that starts or ends at a constant).
  void apply(std::vector<double>& signal) const;
  double cutoffHz() const { return cutoff_hz_; }

 private:
  double cutoff_hz_;
  double b0_, b1_, b2_, a1_, a2_;
};

/// Options of differentiate().
struct DifferentiationOptions {
  double cutoff_hz = 6.0;  ///< low-pass cutoff on the velocities (Hz); ≤ 0: no filter
};

/// A sampled motion's velocities and accelerations (model velocity coordinates, nv each).
struct MotionDerivatives {
  std::vector<VectorX> v;  ///< one per sample
  std::vector<VectorX> a;  ///< one per sample
};

/// Differentiates configurations q_k sampled every dt seconds (see the file comment).
/// \throws std::invalid_argument on fewer than 3 samples, a non-positive dt, a sample of the wrong
/// size or a non-finite coordinate (naming the sample), or a cutoff above 0.8 × the Nyquist frequency.
MotionDerivatives differentiate(const skeleton::Model& model, const std::vector<VectorX>& q, double dt,
                                const DifferentiationOptions& options = {});

}  // namespace mannequin::kinetics
