// The totals of a run of World steps: see run_totals.hpp.
#include "mannequin/sim/run_totals.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace mannequin::sim {

void RunTotals::reset(int mannequins) {
  *this = RunTotals{};
  min_balance_per_mannequin_m.assign(static_cast<std::size_t>(mannequins), kNaN);
}

void RunTotals::add(const World& world, bool ok) {
  ++steps;
  const StepDiagnostics& d = world.diagnostics();
  if (!ok || d.nan) ++nan_steps;
  if (world.physics()) {
    max_penetration_m = std::max(max_penetration_m, d.max_penetration_m);
    max_contacts = std::max(max_contacts, d.contacts);
    contact_sum += d.contacts;
    failed_collision_pairs += d.failed_collision_pairs;
  }
  bool foot = false;
  for (int m = 0; m < world.numMannequins(); ++m) {
    if (world.physics()) {
      const MannequinDiagnostics& md = world.mannequinDiagnostics(m);
      foot = foot || md.foot_contact;
      const double b = md.balance_distance_m;
      if (std::isfinite(b)) {
        if (!(b >= min_balance_distance_m)) min_balance_distance_m = b;  // NaN: the first finite value
        if (static_cast<std::size_t>(m) < min_balance_per_mannequin_m.size()) {
          double& mb = min_balance_per_mannequin_m[static_cast<std::size_t>(m)];
          if (!(b >= mb)) mb = b;
        }
      }
      worst_joint_limit_excess_rad = std::max(worst_joint_limit_excess_rad, md.worst_joint_limit_excess_rad);
      ++mannequin_steps;
      if (md.balance_driving) {
        ++balance_driving_steps;
        if (md.balance_margin_fraction >= 1.0) ++balance_full_margin_steps;
      }
      if (std::isfinite(md.force_margin_n)) {
        if (!(md.force_margin_n >= min_force_margin_n)) min_force_margin_n = md.force_margin_n;  // NaN: the first
        force_margin_sum += md.force_margin_n;
        ++force_margin_samples;
      }
    }
    if (!world.calibrated(m)) continue;
    for (const DrivenFrame& f : world.controlFrames(m)) {
      if (!f.tracked) continue;
      if (f.frame.rfind("hand_", 0) == 0) {
        hand_error_sum += f.position_error;
        ++hand_samples;
      } else if (f.frame.rfind("foot_", 0) == 0) {
        foot_error_sum += f.position_error;
        ++foot_samples;
      }
    }
  }
  if (foot) ++foot_contact_steps;
}

}  // namespace mannequin::sim
