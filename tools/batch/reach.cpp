#include "reach.hpp"

#include "mannequin/core/config.hpp"

namespace mannequin::batch {

std::vector<ReachTarget> loadReachTargets(const std::string& path) {
  const core::ConfigNode root = core::ConfigNode::load(path);
  root.allowOnly({"targets"});
  const core::ConfigNode list = root["targets"];
  std::vector<ReachTarget> out;
  for (const core::ConfigNode& t : list.items()) {
    t.allowOnly({"name", "point", "hand"});
    ReachTarget r;
    r.name = t["name"].str();
    if (r.name.empty()) t["name"].fail("expected a name");
    for (const ReachTarget& o : out)
      if (o.name == r.name) t["name"].fail("a second target named '" + r.name + "'");
    r.point = t["point"].vec3();
    r.side = t["hand"].choice({"left", "right"}) == 0 ? ergonomics::Side::kLeft : ergonomics::Side::kRight;
    out.push_back(r);
  }
  if (out.empty()) list.fail("expected at least one target");
  return out;
}

void ReachOutcome::add(double time_s, const ergonomics::ReachResult& r) {
  ++samples;
  if (r.reachable) ++reached_samples;
  const double margin = r.arm_length - r.distance;
  arm_length_m = r.arm_length;
  if (!(margin <= best_margin_m)) {  // strictly better (or the first): the earliest among equals
    best_margin_m = margin;
    best_time_s = time_s;
    best_distance_m = r.distance;
    best_shoulder = r.shoulder;
  }
}

}  // namespace mannequin::batch
