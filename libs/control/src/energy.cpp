#include "mannequin/control/energy.hpp"

#include <algorithm>
#include <cmath>

namespace mannequin::control {

double EnergyObserver::update(double work, double potential, double dt) {
  // energy given by the internal control beyond the largest energy its potential has held:
  // a true spring gives back at most α·max U (it cannot give more than it stored)
  injected_ += work;
  peak_ = std::max(peak_, alpha_ * potential);
  created_ = injected_ - peak_;
  if (!options_.enabled) return alpha_;
  if (created_ > options_.budget) {
    alpha_ *= std::exp(-options_.decay_per_s * dt);
  } else if (created_ < 0.5 * options_.budget) {
    alpha_ = std::min(1.0, alpha_ + options_.recovery_per_s * dt);
  }
  alpha_ = std::max(alpha_, options_.alpha_min);
  return alpha_;
}

}  // namespace mannequin::control
