// mannequin-batch: report.html, self-contained (inline SVG plots and PNG snapshots, no scripts) (run.hpp).
#include <fmt/format.h>

#include "mannequin/core/text.hpp"
#include "run.hpp"

namespace mannequin::batch {

namespace {

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

}  // namespace

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

}  // namespace mannequin::batch
