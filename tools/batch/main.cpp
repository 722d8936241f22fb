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
#include "run.hpp"

using namespace mannequin;
namespace fs = std::filesystem;

using namespace mannequin::batch;

namespace {

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
