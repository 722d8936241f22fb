// mannequin-batch: summary.json, one object per run (run.hpp).
#include <fmt/format.h>

#include "mannequin/core/text.hpp"
#include "run.hpp"

namespace mannequin::batch {

namespace {

std::string vec3Json(const ergonomics::Vector3& v) { return fmt::format("[{}, {}, {}]", num(v.x()), num(v.y()), num(v.z())); }

std::string series(const std::vector<double>& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + num(v[i]);
  return out + "]";
}

std::string scoreJson(const std::vector<Worst>& all, const long long* hist, int max_score, double max, double mean_score) {
  std::string h = "{";
  for (int k = 1; k <= max_score; ++k) h += fmt::format("{}\"{}\": {}", k > 1 ? ", " : "", k, hist[k]);
  h += "}";
  std::string w = "[";
  const std::vector<Worst> top = worst(all);
  for (std::size_t i = 0; i < top.size(); ++i)
    w += fmt::format("{}{{\"time_s\": {}, \"score\": {}}}", i ? ", " : "", num(top[i].time_s), top[i].score);
  w += "]";
  return fmt::format("{{\"max\": {}, \"mean\": {}, \"histogram\": {}, \"worst_frames\": {}}}", num(max), num(mean_score), h, w);
}

}  // namespace

std::string runJson(const Run& r) {
  const simservice::OfflineSummary& s = r.summary;
  std::string frames = "{";
  for (std::size_t i = 0; i < r.frame_names.size(); ++i)
    frames += fmt::format("{}{}: {{\"mean_m\": {}, \"max_m\": {}, \"samples\": {}}}", i ? ", " : "", core::jsonString(r.frame_names[i]),
                          num(r.frame_n[i] ? r.frame_sum[i] / static_cast<double>(r.frame_n[i]) : kNaN), num(r.frame_n[i] ? r.frame_max[i] : kNaN),
                          r.frame_n[i]);
  frames += "}";
  const simservice::ErgonomicsSummary& e = s.ergonomics.front();
  std::string shots = "[";
  for (std::size_t i = 0; i < r.snapshots.size(); ++i) {
    const batch::Snapshot& p = r.snapshots[i];
    shots += fmt::format("{}{{\"time_s\": {}, \"rula\": {}, \"reba\": {}, \"file\": {}}}", i ? ", " : "", num(p.sample.time_s),
                         p.sample.rula, p.sample.reba, core::jsonString(p.file));
  }
  shots += "]";
  std::string reach = "[";
  for (std::size_t i = 0; i < r.reach.size(); ++i) {
    const batch::ReachOutcome& o = r.reach[i];
    reach += fmt::format(
        "{}{{\"name\": {}, \"hand\": \"{}\", \"point\": {}, \"reached\": {}, \"miss_m\": {}, \"best_margin_m\": {}, "
        "\"best_time_s\": {}, \"best_distance_m\": {}, \"shoulder_at_best\": {}, \"arm_length_m\": {}, \"samples\": {}, "
        "\"reached_samples\": {}}}",
        i ? ", " : "", core::jsonString(o.target.name), ergonomics::toString(o.target.side), vec3Json(o.target.point),
        o.reached() ? "true" : "false", num(o.samples ? o.missM() : kNaN), num(o.best_margin_m), num(o.best_time_s),
        num(o.best_distance_m), vec3Json(o.best_shoulder), num(o.arm_length_m), o.samples, o.reached_samples);
  }
  reach += "]";
  std::string levels_rula, levels_reba, above_rula, above_reba;
  for (std::size_t i = 0; i < e.rula_time_s.size(); ++i) levels_rula += (i ? ", " : "") + num(e.rula_time_s[i]);
  for (std::size_t i = 0; i < e.reba_time_s.size(); ++i) levels_reba += (i ? ", " : "") + num(e.reba_time_s[i]);
  for (std::size_t i = 0; i < e.rula_time_s.size(); ++i) above_rula += (i ? ", " : "") + num(timeAtOrAbove(e.rula_time_s, i));
  for (std::size_t i = 0; i < e.reba_time_s.size(); ++i) above_reba += (i ? ", " : "") + num(timeAtOrAbove(e.reba_time_s, i));
  const auto hand = [&](int side) {
    return fmt::format("{{\"mean\": {}, \"max\": {}, \"max_load_kg\": {}}}", num(e.meanHandForce(side)),
                       num(e.hand_force_samples ? e.hand_force_max_n[static_cast<std::size_t>(side)] : kNaN),
                       num(e.hand_force_samples ? e.hand_load_max_kg[static_cast<std::size_t>(side)] : kNaN));
  };
  return fmt::format(
      "{{\"mannequin_config\": {}, \"label\": {}, \"mannequin\": {}, \"mcap\": {}, {}, "
      "\"samples\": {}, "
      "\"tracking_error\": {{\"per_control_frame\": {}, \"mean_m\": {}, \"max_m\": {}}}, "
      "\"contact_force_n\": {{\"mean\": {}, \"max\": {}, \"p95\": {}}}, "
      "\"rula\": {}, \"rula_time_at_action_level_s\": [{}], \"reba\": {}, \"reba_time_at_action_level_s\": [{}], "
      "\"rula_time_at_or_above_action_level_s\": [{}], \"reba_time_at_or_above_action_level_s\": [{}], "
      "\"hand_force_n\": {{\"left\": {}, \"right\": {}}}, \"kinetics\": {}, "
      "\"series\": {{\"time_s\": {}, \"rula\": {}, \"reba\": {}, \"balance_distance_m\": {}, \"contacts\": {}, \"contact_force_n\": {}, "
      "\"penetration_m\": {}, \"tracking_error_m\": {}, \"hand_force_l_n\": {}, \"hand_force_r_n\": {}}}, \"snapshots\": {}, \"reach\": {}, "
      "\"time_per_step_us\": {{\"mean\": {}, \"max\": {}}}}}",
      core::jsonString(r.config), core::jsonString(r.label), core::jsonString(e.mannequin), core::jsonString(r.mcap),
      simservice::summaryJsonMembers(s), e.samples, frames, num(mean(r.tracking)), num(maxOf(r.tracking)),
      num(mean(r.force)), num(maxOf(r.force)), num(percentile(r.force, 0.95)),
      scoreJson(r.rula_all, r.rula_hist.data(), 7, maxOf(r.rula), mean(r.rula)), levels_rula,
      scoreJson(r.reba_all, r.reba_hist.data(), 15, maxOf(r.reba), mean(r.reba)), levels_reba, above_rula, above_reba, hand(0), hand(1),
      s.kinetics.empty() ? std::string("null") : simservice::kineticsJson(s.kinetics.front()),
      series(r.t), series(r.rula),
      series(r.reba), series(r.balance), series(r.contacts), series(r.force), series(r.penetration), series(r.tracking), series(r.hand_l), series(r.hand_r), shots, reach,
      num(r.step_n ? 1e6 * r.step_wall_sum / static_cast<double>(r.step_n) : kNaN),
      num(1e6 * r.step_wall_max));
}

}  // namespace mannequin::batch
