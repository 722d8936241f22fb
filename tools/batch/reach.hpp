#pragma once
// mannequin-batch: reach targets (a YAML file, --reach): points in world coordinates, each for one hand,
// checked at every scored world sample with ergonomics::Evaluator::reach (the target's distance from the
// shoulder joint centre against the straight arm's length). docs/ergonomics.md, "Reach targets".
//
//   targets:
//     - name: shelf_top          # unique
//       point: [0.45, 0.25, 1.95] # world (m, z up)
//       hand: left               # left | right
#include <limits>
#include <string>
#include <vector>

#include "mannequin/ergonomics/ergonomics.hpp"

namespace mannequin::batch {

struct ReachTarget {
  std::string name;
  ergonomics::Vector3 point = ergonomics::Vector3::Zero();  ///< world (m)
  ergonomics::Side side = ergonomics::Side::kLeft;
};

/// \throws core::ConfigError "FILE:LINE: field 'targets[i].hand': ..." (unknown key, a non-finite or
/// missing point, an unknown hand, two targets of one name, no targets).
std::vector<ReachTarget> loadReachTargets(const std::string& path);

/// One target over a run: the best sample (the one where the target is closest to being in reach).
struct ReachOutcome {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  ReachTarget target;
  long long samples = 0;          ///< samples checked (scored ones)
  long long reached_samples = 0;  ///< of those, with the target within the arm's length
  double arm_length_m = kNaN;
  double best_margin_m = kNaN;    ///< max over samples of arm length − distance (> 0: reached with room to spare)
  double best_time_s = kNaN;      ///< the (earliest) sample of best_margin_m
  double best_distance_m = kNaN;  ///< shoulder-to-target distance there
  ergonomics::Vector3 best_shoulder = ergonomics::Vector3::Constant(kNaN);  ///< shoulder joint centre there (world)

  bool reached() const { return reached_samples > 0; }
  /// By how much it stays out of reach at best (0 when reached).
  double missM() const { return best_margin_m < 0 ? -best_margin_m : 0.0; }
  /// Adds one sample's result.
  void add(double time_s, const ergonomics::ReachResult& r);
};

}  // namespace mannequin::batch
