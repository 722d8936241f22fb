#pragma once
/// \file run_totals.hpp
/// \brief What a run of World steps adds up: the one accumulator of the live sim service's status
/// lines and stop summary and of the offline run's summary (mannequin-simulate --json, mannequin-batch).
/// add() allocates nothing (the per-mannequin vector is sized by reset()).
#include <limits>
#include <vector>

#include "mannequin/sim/world.hpp"

namespace mannequin::sim {

struct RunTotals {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  long long steps = 0, nan_steps = 0;
  // physics on (contacts, balance, limits)
  double max_penetration_m = 0;
  int max_contacts = 0;
  double contact_sum = 0;
  long long failed_collision_pairs = 0;   ///< collision pairs whose narrow phase failed, summed over steps
  long long foot_contact_steps = 0;       ///< steps where a foot of some mannequin touches the floor
  double min_balance_distance_m = kNaN;   ///< over every mannequin; NaN: never a support polygon
  std::vector<double> min_balance_per_mannequin_m;  ///< per mannequin; NaN: never a support polygon
  double worst_joint_limit_excess_rad = 0;
  double min_force_margin_n = kNaN;       ///< NaN: never evaluated (physics.force_margin_period 0)
  double force_margin_sum = 0;
  long long force_margin_samples = 0;
  // the balance controller: mannequin-steps it drove, and of those the ones with the whole margin held
  long long mannequin_steps = 0, balance_driving_steps = 0, balance_full_margin_steps = 0;
  // tracking of the calibrated mannequins' tracked hand_* and foot_* control frames
  double hand_error_sum = 0, foot_error_sum = 0;
  long long hand_samples = 0, foot_samples = 0;

  /// Zeroes the totals for a World of `mannequins` mannequins.
  void reset(int mannequins);
  /// Adds the World's last step (World::step returned `ok`).
  void add(const World& world, bool ok);

  double meanContacts() const { return steps > 0 ? contact_sum / static_cast<double>(steps) : 0.0; }
  double footContactFraction() const {
    return steps > 0 ? static_cast<double>(foot_contact_steps) / static_cast<double>(steps) : 0.0;
  }
  double meanHandError() const { return hand_samples > 0 ? hand_error_sum / static_cast<double>(hand_samples) : kNaN; }
  double meanFootError() const { return foot_samples > 0 ? foot_error_sum / static_cast<double>(foot_samples) : kNaN; }
  double balanceDrivingFraction() const {
    return mannequin_steps > 0 ? static_cast<double>(balance_driving_steps) / static_cast<double>(mannequin_steps) : kNaN;
  }
  double balanceFullMarginFraction() const {
    return balance_driving_steps > 0 ? static_cast<double>(balance_full_margin_steps) / static_cast<double>(balance_driving_steps)
                                     : kNaN;
  }
  double meanForceMargin() const {
    return force_margin_samples > 0 ? force_margin_sum / static_cast<double>(force_margin_samples) : kNaN;
  }
};

}  // namespace mannequin::sim
