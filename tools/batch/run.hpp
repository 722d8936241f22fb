#pragma once
// mannequin-batch's data: one run per mannequin config (what the summary and the report say about it), the
// snapshots' settings, and the statistics both use. summary.cpp writes summary.json, report.cpp report.html.
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mannequin/simservice/offline.hpp"
#include "reach.hpp"
#include "snapshots.hpp"

namespace mannequin::batch {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kWorst = 10;  // worst frames listed per score
constexpr double kSnapshotGapS = 0.5;  // two snapshots of one run are at least this far apart in time

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
  std::vector<Snapshot> snapshots;
  std::unique_ptr<ergonomics::Evaluator> reach_evaluator;  // the reach targets' (one per run: it keeps kinematics)
  std::vector<ReachOutcome> reach;                   // per target of --reach
};

/// Snapshots of the whole batch: rendered, or why not.
struct SnapshotInfo {
  int count = 0;  // asked per run (0: none asked)
  int width = 0, height = 0;
  std::string view;
  bool rendered = false;
  std::string error;  // why none were rendered (no headless OpenGL context)
  std::string renderer;  // GL_RENDERER | GL_VERSION
};

//---- statistics of a series (non-finite samples left out; NaN when none is left) ----
double mean(const std::vector<double>& v);
double maxOf(const std::vector<double>& v);
double minOf(const std::vector<double>& v);
double percentile(std::vector<double> v, double p);
/// Time at action level i or above, from the times at each level.
template <std::size_t N>
double timeAtOrAbove(const std::array<double, N>& at, std::size_t i) {
  double t = 0;
  for (std::size_t k = i; k < N; ++k) t += at[k];
  return t;
}

/// The kWorst highest scores, the earliest first among equals.
std::vector<Worst> worst(std::vector<Worst> all);

/// A JSON number (null when not finite). %.17g: the same double prints the same text.
std::string num(double v);
/// A short number for the report ("–" when not finite).
std::string shortNum(double v, int digits = 3);

/// One run's object in summary.json (summary.cpp).
std::string runJson(const Run& r);
/// The self-contained HTML report of the runs (report.cpp).
std::string reportHtml(const std::vector<Run>& runs, const std::string& mocap, const SnapshotInfo& shots);

}  // namespace mannequin::batch
