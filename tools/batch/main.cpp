// mannequin-batch: a capture (BVH or C3D) through the sim service's World offline (services/sim
// OfflineRun, as mannequin-simulate), on one mannequin or several side by side (--compare), with the
// ergonomic scores of libs/ergonomics per world sample. Writes DIR/run.mcap (DIR/<mannequin>/run.mcap
// when comparing), DIR/summary.json and DIR/report.html (self-contained: inline SVG and PNG, no scripts),
// with pictures of the worst postures rendered off-screen (snapshots.hpp) in DIR/snapshots/ and in the report.
// Everything is written in DIR/.partial first and moved into DIR at the end; a failure removes it.
// See docs/ergonomics.md, "Batch reports".
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "mannequin/core/main.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/core/text.hpp"
#include "mannequin/simservice/offline.hpp"
#include "reach.hpp"
#include "snapshots.hpp"

using namespace mannequin;
namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kWorst = 10;  // worst frames listed per score
constexpr double kSnapshotGapS = 0.5;  // two snapshots of one run are at least this far apart in time

/// A JSON number (null when not finite). %.17g: the same double prints the same text.
std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : "null"; }
/// A short number for the report.
std::string shortNum(double v, int digits = 3) { return std::isfinite(v) ? fmt::format("{:.{}f}", v, digits) : "–"; }

std::string html(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

struct Worst {
  double time_s;
  int score;
};

/// One mannequin config's run: what the report and summary.json say about it.
struct Run {
  std::string config, label, mcap;  // mcap relative to DIR
  std::unique_ptr<simservice::OfflineRun> offline;
  simservice::OfflineSummary summary;
  // per world sample (the first mannequin of the sim config)
  std::vector<double> t, rula, reba, balance, contacts, force, penetration, tracking, hand_l, hand_r;
  std::vector<Worst> rula_all, reba_all;
  std::array<long long, 8> rula_hist{};   // grand score 1..7
  std::array<long long, 16> reba_hist{};  // score 1..15
  // per control frame, over the calibrated steps where it was tracked
  std::vector<std::string> frame_names;
  std::vector<double> frame_sum, frame_max;
  std::vector<long long> frame_n;
  double step_wall_sum = 0, step_wall_max = 0;
  long long step_n = 0;
  std::vector<batch::Snapshot> snapshots;
  std::unique_ptr<ergonomics::Evaluator> reach_evaluator;  // the reach targets' (one per run: it keeps kinematics)
  std::vector<batch::ReachOutcome> reach;                   // per target of --reach
};

std::string vec3Json(const ergonomics::Vector3& v) { return fmt::format("[{}, {}, {}]", num(v.x()), num(v.y()), num(v.z())); }

/// Snapshots of the whole batch: rendered, or why not.
struct SnapshotInfo {
  int count = 0;  // asked per run (0: none asked)
  int width = 0, height = 0;
  std::string view;
  bool rendered = false;
  std::string error;  // why none were rendered (no headless OpenGL context)
  std::string renderer;  // GL_RENDERER | GL_VERSION
};

double mean(const std::vector<double>& v) {
  double s = 0;
  long long n = 0;
  for (double x : v)
    if (std::isfinite(x)) s += x, ++n;
  return n ? s / static_cast<double>(n) : kNaN;
}
double maxOf(const std::vector<double>& v) {
  double m = kNaN;
  for (double x : v)
    if (std::isfinite(x) && !(x <= m)) m = x;
  return m;
}
double minOf(const std::vector<double>& v) {
  double m = kNaN;
  for (double x : v)
    if (std::isfinite(x) && !(x >= m)) m = x;
  return m;
}
double percentile(std::vector<double> v, double p) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::min<double>(static_cast<double>(v.size() - 1), std::floor(p * static_cast<double>(v.size()))))];
}

/// Time at action level i or above, from the times at each level.
template <std::size_t N>
double timeAtOrAbove(const std::array<double, N>& at, std::size_t i) {
  double t = 0;
  for (std::size_t k = i; k < N; ++k) t += at[k];
  return t;
}

std::vector<Worst> worst(std::vector<Worst> all) {
  std::stable_sort(all.begin(), all.end(), [](const Worst& a, const Worst& b) { return a.score > b.score; });
  if (all.size() > kWorst) all.resize(kWorst);
  return all;
}

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
      "{{\"mannequin_config\": {}, \"label\": {}, \"mannequin\": {}, \"mcap\": {}, \"frames\": {}, \"steps\": {}, \"sim_time_s\": {}, "
      "\"samples\": {}, \"nan_steps\": {}, \"lcp_failures\": {}, "
      "\"tracking_error\": {{\"per_control_frame\": {}, \"mean_m\": {}, \"max_m\": {}}}, "
      "\"max_penetration_m\": {}, \"min_balance_distance_m\": {}, \"max_contacts\": {}, \"mean_contacts\": {}, "
      "\"foot_contact_fraction\": {}, "
      "\"contact_force_n\": {{\"mean\": {}, \"max\": {}, \"p95\": {}}}, "
      "\"rula\": {}, \"rula_time_at_action_level_s\": [{}], \"reba\": {}, \"reba_time_at_action_level_s\": [{}], "
      "\"rula_time_at_or_above_action_level_s\": [{}], \"reba_time_at_or_above_action_level_s\": [{}], "
      "\"hand_force_n\": {{\"left\": {}, \"right\": {}}}, \"min_force_margin_n\": {}, "
      "\"series\": {{\"time_s\": {}, \"rula\": {}, \"reba\": {}, \"balance_distance_m\": {}, \"contacts\": {}, \"contact_force_n\": {}, "
      "\"penetration_m\": {}, \"tracking_error_m\": {}, \"hand_force_l_n\": {}, \"hand_force_r_n\": {}}}, \"snapshots\": {}, \"reach\": {}, "
      "\"wall_s\": {}, \"realtime_factor\": {}, \"time_per_step_us\": {{\"mean\": {}, \"max\": {}}}}}",
      core::jsonString(r.config), core::jsonString(r.label), core::jsonString(e.mannequin), core::jsonString(r.mcap), s.frames, s.steps,
      num(s.sim_time_s), e.samples, s.nan_steps, s.lcp_failures, frames, num(mean(r.tracking)), num(maxOf(r.tracking)),
      num(s.max_penetration_m), num(s.min_balance_distance_m), s.max_contacts, num(s.meanContacts()), num(s.footContactFraction()),
      num(mean(r.force)), num(maxOf(r.force)), num(percentile(r.force, 0.95)),
      scoreJson(r.rula_all, r.rula_hist.data(), 7, maxOf(r.rula), mean(r.rula)), levels_rula,
      scoreJson(r.reba_all, r.reba_hist.data(), 15, maxOf(r.reba), mean(r.reba)), levels_reba, above_rula, above_reba, hand(0), hand(1),
      num(s.min_force_margin_n), series(r.t), series(r.rula),
      series(r.reba), series(r.balance), series(r.contacts), series(r.force), series(r.penetration), series(r.tracking), series(r.hand_l), series(r.hand_r), shots, reach,
      num(s.wall_s), num(s.realtimeFactor()), num(r.step_n ? 1e6 * r.step_wall_sum / static_cast<double>(r.step_n) : kNaN),
      num(1e6 * r.step_wall_max));
}

/// An inline SVG line plot of y(t) (NaN breaks the line), fixed y range if lo < hi given.
std::string plot(const std::string& title, const std::vector<double>& t, const std::vector<double>& y, double lo, double hi,
                 const char* colour) {
  const double W = 420, H = 160, L = 44, R = 8, T = 20, B = 24;
  if (!(lo < hi)) {
    lo = minOf(y), hi = maxOf(y);
    if (!std::isfinite(lo)) lo = 0, hi = 1;
    if (hi - lo < 1e-9) lo -= 0.5, hi += 0.5;
  }
  const double t0 = t.empty() ? 0 : t.front(), t1 = t.empty() || t.back() <= t0 ? t0 + 1 : t.back();
  const auto X = [&](double v) { return L + (v - t0) / (t1 - t0) * (W - L - R); };
  const auto Y = [&](double v) { return T + (hi - std::clamp(v, lo, hi)) / (hi - lo) * (H - T - B); };
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" role=\"img\">"
      "<title>{2}</title><text x=\"{3}\" y=\"14\" font-size=\"12\">{2}</text>"
      "<rect x=\"{3}\" y=\"{4}\" width=\"{5}\" height=\"{6}\" fill=\"none\" stroke=\"#999\"/>"
      "<text x=\"{7}\" y=\"{8}\" font-size=\"10\" text-anchor=\"end\">{9}</text>"
      "<text x=\"{7}\" y=\"{10}\" font-size=\"10\" text-anchor=\"end\">{11}</text>"
      "<text x=\"{3}\" y=\"{12}\" font-size=\"10\">{13} s</text>"
      "<text x=\"{14}\" y=\"{12}\" font-size=\"10\" text-anchor=\"end\">{15} s</text>",
      W, H, html(title), L, T, W - L - R, H - T - B, L - 3, T + 8, shortNum(hi, 2), H - B, shortNum(lo, 2), H - 8, shortNum(t0, 1),
      W - R, shortNum(t1, 1));
  std::string pts;
  const auto flush = [&] {
    if (!pts.empty()) svg += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\" points=\"{}\"/>", colour, pts);
    pts.clear();
  };
  for (std::size_t i = 0; i < t.size() && i < y.size(); ++i) {
    if (!std::isfinite(y[i])) {
      flush();
      continue;
    }
    pts += fmt::format("{}{:.1f},{:.1f}", pts.empty() ? "" : " ", X(t[i]), Y(y[i]));
  }
  flush();
  return svg + "</svg>";
}

std::string reportHtml(const std::vector<Run>& runs, const std::string& mocap, const SnapshotInfo& shots) {
  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>mannequin-batch report</title>"
      "<style>body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse;margin:0.5em 0}"
      "td,th{border:1px solid #ccc;padding:2px 8px;text-align:right;vertical-align:top}th{background:#f3f3f3}"
      ".cols{display:flex;gap:1.5em;flex-wrap:wrap}.col{flex:1}figure{margin:0.5em 0}figcaption{font-size:90%}"
      "img{border:1px solid #ccc;max-width:100%;height:auto}</style></head><body>\n";
  h += "<h1>mannequin-batch report</h1>\n<p>Capture <code>" + html(mocap) + "</code>; " + std::to_string(runs.size()) +
       " mannequin" + (runs.size() > 1 ? "s" : "") +
       ". Scores: RULA grand score and REBA score of the worse side, per world sample (libs/ergonomics; the load in "
       "each hand from the World's grasp and contact forces on it, not static, not repeated). Hand force: the magnitude "
       "of the force on the hand segment. Balance distance: signed, &gt; 0 inside the support.</p>\n";
  // the key numbers, mannequins side by side
  h += "<h2>Summary</h2>\n<table id=\"summary\"><tr><th></th>";
  for (const Run& r : runs) h += "<th class=\"mannequin\">" + html(r.label) + "</th>";
  h += "</tr>\n";
  const auto row = [&](const std::string& name, auto value) {
    h += "<tr><th>" + name + "</th>";
    for (const Run& r : runs) h += "<td>" + value(r) + "</td>";
    h += "</tr>\n";
  };
  row("simulated (s)", [](const Run& r) { return shortNum(r.summary.sim_time_s, 2); });
  row("samples", [](const Run& r) { return std::to_string(r.t.size()); });
  row("RULA max / mean", [](const Run& r) { return shortNum(maxOf(r.rula), 0) + " / " + shortNum(mean(r.rula), 2); });
  row("REBA max / mean", [](const Run& r) { return shortNum(maxOf(r.reba), 0) + " / " + shortNum(mean(r.reba), 2); });
  row("RULA time at action levels 1–4 (s)", [](const Run& r) {
    const auto& a = r.summary.ergonomics.front().rula_time_s;
    return fmt::format("{:.2f} / {:.2f} / {:.2f} / {:.2f}", a[0], a[1], a[2], a[3]);
  });
  row("RULA time at action level ≥ 2 / ≥ 3 / 4 (s)", [](const Run& r) {
    const auto& a = r.summary.ergonomics.front().rula_time_s;
    return fmt::format("{:.2f} / {:.2f} / {:.2f}", timeAtOrAbove(a, 1), timeAtOrAbove(a, 2), timeAtOrAbove(a, 3));
  });
  row("REBA time at action level ≥ 2 / ≥ 3 / 4 (s)", [](const Run& r) {
    const auto& a = r.summary.ergonomics.front().reba_time_s;
    return fmt::format("{:.2f} / {:.2f} / {:.2f}", timeAtOrAbove(a, 2), timeAtOrAbove(a, 3), timeAtOrAbove(a, 4));
  });
  row("hand force left mean / max (N)", [](const Run& r) {
    const auto& e = r.summary.ergonomics.front();
    return shortNum(e.meanHandForce(0), 1) + " / " + shortNum(e.hand_force_samples ? e.hand_force_max_n[0] : kNaN, 1);
  });
  row("hand force right mean / max (N)", [](const Run& r) {
    const auto& e = r.summary.ergonomics.front();
    return shortNum(e.meanHandForce(1), 1) + " / " + shortNum(e.hand_force_samples ? e.hand_force_max_n[1] : kNaN, 1);
  });
  row("min balance distance (m)", [](const Run& r) { return shortNum(r.summary.min_balance_distance_m, 4); });
  row("min force margin (N)", [](const Run& r) { return shortNum(r.summary.min_force_margin_n, 1); });
  row("max penetration (mm)", [](const Run& r) { return shortNum(1e3 * r.summary.max_penetration_m, 2); });
  row("contacts max / mean", [](const Run& r) {
    return std::to_string(r.summary.max_contacts) + " / " + shortNum(r.summary.meanContacts(), 1);
  });
  row("contact force mean / max (N)", [](const Run& r) { return shortNum(mean(r.force), 1) + " / " + shortNum(maxOf(r.force), 1); });
  row("tracking error mean / max (mm)", [](const Run& r) {
    return shortNum(1e3 * mean(r.tracking), 1) + " / " + shortNum(1e3 * maxOf(r.tracking), 1);
  });
  h += "</table>\n";
  if (!runs.front().reach.empty()) {
    h += "<h2>Reach</h2>\n<p>Each target against the hand's reach at every scored sample: its distance from the shoulder "
         "joint centre against the straight arm (shoulder, elbow, wrist, palm point); the best sample of the run.</p>\n"
         "<table id=\"reach\"><tr><th>target</th><th>hand</th><th>point (m)</th>";
    for (const Run& r : runs) h += "<th class=\"mannequin\">" + html(r.label) + "</th>";
    h += "</tr>\n";
    for (std::size_t k = 0; k < runs.front().reach.size(); ++k) {
      const batch::ReachTarget& t = runs.front().reach[k].target;
      h += fmt::format("<tr><th>{}</th><td>{}</td><td>{:.3f}, {:.3f}, {:.3f}</td>", html(t.name), ergonomics::toString(t.side),
                       t.point.x(), t.point.y(), t.point.z());
      for (const Run& r : runs) {
        const batch::ReachOutcome& o = r.reach[k];
        if (o.samples == 0)
          h += "<td>–</td>";
        else if (o.reached())
          h += fmt::format("<td class=\"reached\">reached, {:.3f} m to spare at {:.3f} s; in reach {:.0f} % of the time</td>",
                           o.best_margin_m, o.best_time_s, 100.0 * static_cast<double>(o.reached_samples) / static_cast<double>(o.samples));
        else
          h += fmt::format("<td class=\"missed\">missed by {:.3f} m (closest at {:.3f} s)</td>", o.missM(), o.best_time_s);
      }
      h += "</tr>\n";
    }
    h += "</table>\n";
  }
  if (shots.count > 0) {  // the pictures first: what the numbers below are about
    h += "<h2>Worst postures</h2>\n";
    if (!shots.rendered) {
      h += "<p class=\"no-snapshots\">The snapshots of the worst postures were not rendered: no headless OpenGL context "
           "could be made here (" + html(shots.error) + "). The postures are in the run's MCAP recording "
           "(<code>mannequin-render --from run.mcap --headless</code> draws them where OpenGL is available).</p>\n";
    } else {
      h += fmt::format("<p>The {} worst samples of each run by RULA (then REBA), at least {:.1f} s apart, drawn from the "
                       "recorded sim.world state with the view <code>{}</code> (also in <code>snapshots/</code>; OpenGL: {}).</p>\n",
                       shots.count, kSnapshotGapS, html(shots.view), html(shots.renderer));
      h += "<div class=\"cols\">\n";
      for (const Run& r : runs) {
        h += "<div class=\"col\"><h3>" + html(r.label) + "</h3>\n";
        for (const batch::Snapshot& p : r.snapshots)
          h += fmt::format("<figure class=\"snapshot\"><img src=\"data:image/png;base64,{}\" width=\"{}\" height=\"{}\" "
                           "alt=\"{} at {:.3f} s\"><figcaption>t = {:.3f} s: RULA {}, REBA {} ({})</figcaption></figure>\n",
                           batch::base64(p.png), shots.width, shots.height, html(r.label), p.sample.time_s, p.sample.time_s,
                           p.sample.rula, p.sample.reba, html(p.file));
        h += "</div>\n";
      }
      h += "</div>\n";
    }
  }
  h += "<h2>Time series</h2>\n<div class=\"cols\">\n";
  for (const Run& r : runs) {
    h += "<div class=\"col\"><h3>" + html(r.label) + "</h3>\n";
    h += plot("RULA grand score", r.t, r.rula, 1, 7, "#c0392b") + "\n";
    h += plot("REBA score", r.t, r.reba, 1, 15, "#d35400") + "\n";
    h += plot("balance distance (m)", r.t, r.balance, 0, 0, "#2471a3") + "\n";
    h += plot("contacts", r.t, r.contacts, 0, 0, "#1e8449") + "\n";
    h += plot("hand force left (N)", r.t, r.hand_l, 0, 0, "#7d3c98") + "\n";
    h += plot("hand force right (N)", r.t, r.hand_r, 0, 0, "#117a65") + "\n";
    h += "</div>\n";
  }
  h += "</div>\n<h2>Worst frames</h2>\n<div class=\"cols\">\n";
  for (const Run& r : runs) {
    const std::vector<Worst> wr = worst(r.rula_all), wb = worst(r.reba_all);
    h += "<div class=\"col\"><h3>" + html(r.label) + "</h3>\n<table class=\"worst-frames\"><tr><th>#</th><th>RULA time (s)</th>"
         "<th>RULA</th><th>REBA time (s)</th><th>REBA</th></tr>\n";
    for (std::size_t i = 0; i < std::max(wr.size(), wb.size()); ++i) {
      h += "<tr><td>" + std::to_string(i + 1) + "</td>";
      h += i < wr.size() ? "<td>" + shortNum(wr[i].time_s, 3) + "</td><td>" + std::to_string(wr[i].score) + "</td>" : "<td></td><td></td>";
      h += i < wb.size() ? "<td>" + shortNum(wb[i].time_s, 3) + "</td><td>" + std::to_string(wb[i].score) + "</td>" : "<td></td><td></td>";
      h += "</tr>\n";
    }
    h += "</table></div>\n";
  }
  h += "</div>\n";
  return h + "</body></html>\n";
}

void writeFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::vector<std::string> splitComma(const std::string& s) {
  std::vector<std::string> out;
  std::size_t a = 0;
  while (a <= s.size()) {
    const std::size_t b = std::min(s.find(',', a), s.size());
    if (b > a) out.push_back(s.substr(a, b - a));
    a = b + 1;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-batch: a capture through the simulated World offline on one or several mannequins, with\n"
               "RULA/REBA per sample; writes DIR/run.mcap, DIR/summary.json and DIR/report.html (self-contained)."};
  std::string mocap, config = "configs/sim/sim_demo.yaml", mannequin, compare, scene, scenario, out, mapping = "configs/mappings/c3d_sample01.yaml",
                     log_level = "warn";
  double duration = -1;
  int snapshots = 3;
  std::string reach_file;
  std::string snapshot_size = "640x360", view_file = "configs/views/desktop.yaml";
  app.add_option("--mocap", mocap,
                 "capture: .bvh (the sim config's mocap map and bodies), .c3d (--mapping) or .mcap (its mocap.frame, e.g. from "
                 "mannequin-record); default: the sim config's own capture");
  app.add_option("--config,-c", config, "sim config (configs/sim/sim_*.yaml)")->capture_default_str();
  app.add_option("--mannequin", mannequin, "mannequin config (configs/mannequins/*.yaml)")->required();
  app.add_option("--compare", compare, "more mannequin configs, comma separated, run on the same capture side by side");
  app.add_option("--scene", scene, "scene file (configs/scenes/*.yaml): turns the physics on with this scene");
  app.add_option("--scenario", scenario, "scenario file (configs/scenarios/*.yaml) replacing the sim config's");
  app.add_option("--mapping", mapping, "C3D marker-cluster mapping (configs/mappings/*.yaml)")->capture_default_str();
  app.add_option("--out,-o", out, "output directory")->required();
  app.add_option("--duration", duration, "seconds of simulation (default: the whole capture)")->check(CLI::PositiveNumber);
  app.add_option("--reach", reach_file, "reach targets: YAML with targets: [{name, point: [x, y, z] (world, m), hand: left|right}]");
  app.add_option("--snapshots", snapshots, "pictures of the worst postures per mannequin, rendered off-screen (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0, 20));
  app.add_option("--snapshot-size", snapshot_size, "snapshot size WIDTHxHEIGHT (pixels)")->capture_default_str();
  app.add_option("--view", view_file, "view file of the snapshots' camera (configs/views/*.yaml)")->capture_default_str();
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")->capture_default_str()->check(core::logLevelCheck());
  return core::runMain(app, argc, argv, [&]() -> int {
    core::setupLogging(log_level);
    std::vector<std::string> configs{mannequin};
    for (const std::string& c : splitComma(compare))
      if (std::find(configs.begin(), configs.end(), c) == configs.end()) configs.push_back(c);
    const bool comparing = configs.size() > 1;
    const fs::path dir(out), partial = fs::path(out) / ".partial";
    std::vector<Run> runs(configs.size());
    SnapshotInfo shots;
    shots.count = snapshots;
    render::ViewConfig view;
    try {
      const auto size = render::parseSize(snapshot_size);
      shots.width = size[0];
      shots.height = size[1];
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--snapshot-size", e.what());
    }
    std::vector<batch::ReachTarget> targets;
    try {
      // old results first: a failed run leaves nothing that looks like this run's report
      fs::create_directories(dir);
      for (const char* f : {"summary.json", "report.html"}) fs::remove(dir / f);
      fs::remove_all(dir / "snapshots");
      fs::remove_all(partial);
      fs::create_directories(partial);
      for (std::size_t i = 0; i < configs.size(); ++i) {
        Run& r = runs[i];
        r.config = configs[i];
        r.label = fs::path(configs[i]).stem().string();
        for (std::size_t j = 0; j < i; ++j)
          if (runs[j].label == r.label) throw simservice::OfflineInputError(configs[i] + ": a second mannequin config named " + r.label);
        r.mcap = comparing ? r.label + "/run.mcap" : "run.mcap";
        fs::create_directories((partial / r.mcap).parent_path());
        simservice::OfflineOptions o;
        o.config = config;
        o.mocap = mocap;
        o.c3d_mapping = mapping;
        o.mannequin = configs[i];
        o.scene = scene;
        o.scenario = scenario;
        o.duration = duration;
        o.out = (partial / r.mcap).string();
        o.progress = ::isatty(STDERR_FILENO) == 1;
        o.progress_label = comparing ? fmt::format("{} ({}/{}) ", r.label, i + 1, configs.size()) : "";
        r.offline = std::make_unique<simservice::OfflineRun>(o);  // every input read before the first run
      }
      if (!reach_file.empty()) {
        try {
          targets = batch::loadReachTargets(core::findData(reach_file));
        } catch (const std::exception& e) {
          throw simservice::OfflineInputError(e.what());
        }
        for (Run& r : runs) {
          r.reach_evaluator = std::make_unique<ergonomics::Evaluator>(r.offline->world().model(0));
          for (const batch::ReachTarget& t : targets) r.reach.push_back({t});
        }
      }
      if (shots.count > 0) {
        try {
          shots.view = view_file;
          view = render::loadView(core::findData(view_file));
        } catch (const std::exception& e) {
          throw simservice::OfflineInputError(e.what());
        }
      }
      for (Run& r : runs) {
        r.summary = r.offline->run(
            [&r](const sim::World& w, const std::vector<const ergonomics::Assessment*>& a) {
              r.t.push_back(w.time());
              const ergonomics::Assessment* x = a.empty() ? nullptr : a.front();
              const double rula = x ? std::max(x->rula[0].grand, x->rula[1].grand) : kNaN;
              const double reba = x ? std::max(x->reba[0].score, x->reba[1].score) : kNaN;
              r.rula.push_back(rula);
              r.reba.push_back(reba);
              if (x) {
                ++r.rula_hist[static_cast<std::size_t>(rula)];
                ++r.reba_hist[static_cast<std::size_t>(reba)];
                r.rula_all.push_back({w.time(), static_cast<int>(rula)});
                r.reba_all.push_back({w.time(), static_cast<int>(reba)});
                for (batch::ReachOutcome& o : r.reach) o.add(w.time(), r.reach_evaluator->reach(w.q(0), o.target.side, o.target.point));
              }
              double force = 0;
              for (const sim::ContactReport& c : w.contacts()) force += c.normal_force;
              r.force.push_back(w.physics() ? force : kNaN);
              const auto hands = w.physics() && x ? w.handForces(0) : std::array<math::Vector3, 2>{};
              r.hand_l.push_back(w.physics() && x ? hands[0].norm() : kNaN);
              r.hand_r.push_back(w.physics() && x ? hands[1].norm() : kNaN);
              r.penetration.push_back(w.physics() ? w.diagnostics().max_penetration_m : kNaN);
              r.balance.push_back(w.physics() ? w.mannequinDiagnostics(0).balance_distance_m : kNaN);
              r.contacts.push_back(w.physics() ? w.mannequinDiagnostics(0).contacts : kNaN);
              double err = 0;
              int n = 0;
              if (w.calibrated(0))
                for (const sim::DrivenFrame& f : w.controlFrames(0))
                  if (f.tracked) err += f.position_error, ++n;
              r.tracking.push_back(n ? err / n : kNaN);
            },
            [&r](const sim::World& w, double step_wall_s) {
              r.step_wall_sum += step_wall_s;
              r.step_wall_max = std::max(r.step_wall_max, step_wall_s);
              ++r.step_n;
              if (!w.calibrated(0)) return;
              const auto& frames = w.controlFrames(0);
              if (r.frame_names.empty())
                for (const sim::DrivenFrame& f : frames) {
                  r.frame_names.push_back(f.frame);
                  r.frame_sum.push_back(0);
                  r.frame_max.push_back(0);
                  r.frame_n.push_back(0);
                }
              for (std::size_t i = 0; i < frames.size() && i < r.frame_names.size(); ++i)
                if (frames[i].tracked) {
                  r.frame_sum[i] += frames[i].position_error;
                  r.frame_max[i] = std::max(r.frame_max[i], frames[i].position_error);
                  ++r.frame_n[i];
                }
            });
      }
      // the worst postures, drawn from the recorded states; without an OpenGL context the report says so
      if (shots.count > 0) {
        std::unique_ptr<batch::SnapshotRenderer> renderer;
        try {
          renderer = std::make_unique<batch::SnapshotRenderer>(view, shots.width, shots.height);
          shots.rendered = true;
          shots.renderer = renderer->description();
        } catch (const render::RenderError& e) {
          shots.error = e.what();
          std::fprintf(stderr, "mannequin-batch: no snapshots: %s\n", e.what());
        }
        for (Run& r : runs) {
          if (!renderer) break;
          std::vector<batch::ScoredSample> scored;
          for (std::size_t i = 0; i < r.t.size(); ++i)
            if (std::isfinite(r.rula[i])) scored.push_back({r.t[i], static_cast<int>(r.rula[i]), static_cast<int>(r.reba[i])});
          const sim::World& w = r.offline->world();
          render::SceneAssets assets;
          if (r.offline->config().world.physics.enabled) assets.scene = r.offline->config().world.physics.scene;
          for (int m = 0; m < w.numMannequins(); ++m) assets.addModel(w.name(m), w.model(m));
          r.snapshots = renderer->render((partial / r.mcap).string(), batch::pickWorst(scored, shots.count, kSnapshotGapS), assets,
                                         (partial / "snapshots").string(), "snapshots", r.label);
        }
      }
      const std::string capture = mocap.empty() ? runs.front().offline->captureFile() : mocap;
      std::string json = fmt::format("{{\"tool\": \"mannequin-batch\", \"mocap\": {}, \"config\": {}, \"scene\": {}, \"scenario\": {}, \"duration_s\": {}, "
                                     "\"sample_rate_hz\": {}, \"snapshots\": {}, \"wall_clock_keys\": [\"wall_s\", \"realtime_factor\", \"time_per_step_us\"], "
                                     "\"runs\": [",
                                     core::jsonString(capture), core::jsonString(config), scene.empty() ? "null" : core::jsonString(scene),
                                     scenario.empty() ? "null" : core::jsonString(scenario),
                                     num(duration), num(runs.front().offline->config().world_rate),
                                     fmt::format("{{\"per_run\": {}, \"size\": [{}, {}], \"view\": {}, \"rendered\": {}, \"error\": {}}}",
                                                 shots.count, shots.width, shots.height, shots.count > 0 ? core::jsonString(view_file) : "null",
                                                 shots.rendered ? "true" : "false",
                                                 shots.error.empty() ? "null" : core::jsonString(shots.error)));
      for (std::size_t i = 0; i < runs.size(); ++i) json += (i ? ", " : "") + runJson(runs[i]);
      json += "]}\n";
      writeFile(partial / "summary.json", json);
      writeFile(partial / "report.html", reportHtml(runs, capture, shots));
      // complete: into DIR (the report last)
      for (const Run& r : runs) {
        fs::create_directories((dir / r.mcap).parent_path());
        fs::rename(partial / r.mcap, dir / r.mcap);
      }
      if (fs::exists(partial / "snapshots")) fs::rename(partial / "snapshots", dir / "snapshots");
      fs::rename(partial / "summary.json", dir / "summary.json");
      fs::rename(partial / "report.html", dir / "report.html");
      fs::remove_all(partial);
    } catch (const simservice::OfflineInputError& e) {
      std::error_code ec;
      fs::remove_all(partial, ec);
      std::fprintf(stderr, "mannequin-batch: %s\n", e.what());
      return core::kExitUsage;
    } catch (...) {
      std::error_code ec;
      fs::remove_all(partial, ec);
      throw;
    }
    for (const Run& r : runs) {
      const auto& e = r.summary.ergonomics.front();
      std::printf("%-12s %.2f s simulated, %.1fx real time; RULA max %d, REBA max %d; min balance %.4f m\n", r.label.c_str(),
                  r.summary.sim_time_s, r.summary.realtimeFactor(), e.rula_max, e.reba_max, r.summary.min_balance_distance_m);
    }
    std::printf("wrote %s, %s\n", (dir / "summary.json").c_str(), (dir / "report.html").c_str());
    return core::kExitOk;
  });
}
