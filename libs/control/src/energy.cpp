#include "mannequin/control/energy.hpp"

#include <algorithm>
#include <cmath>

namespace mannequin::control {

double EnergyObserver::update(double work, double potential, double dt) {
  if (!has_potential_) {
    // first call: only the potential's reference
    potential_ = potential;
    has_potential_ = true;
    return alpha_;
  }
  // energy created by the internal control beyond its potential αU
  created_ += work + alpha_ * (potential - potential_);
  potential_ = potential;
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
