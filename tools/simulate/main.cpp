// mannequin-simulate: the sim service's World in one process, without the network: a capture's frames
// fed at their capture times, the World stepped as fast as possible (deterministic, like the service's
// replay mode), a summary of the run (human or --json), optionally the sim.world messages in an MCAP file
// (the v1 messages mannequin-record writes; mannequin-replay reads it). See docs/cluster.md.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/collision/scene.hpp"
#include "mannequin/core/main.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/core/text.hpp"
#include "mannequin/ergonomics/ergonomics.hpp"
#include "mannequin/mocap/bvh_source.hpp"
#include "mannequin/mocap/source.hpp"
#include "mannequin/proto/schema.hpp"
#include "mannequin/recording/mcap_writer.hpp"
#include "mannequin/simservice/config.hpp"
#include "mannequin/simservice/messages.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/topics.hpp"

using namespace mannequin;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Per mannequin, the postures' ergonomic scores over the run (RULA and REBA of the worse side, sampled
/// at the world rate once calibrated; libs/ergonomics with its default task input: no load, not static,
/// not repeated — what a capture cannot say).
struct ErgonomicsSummary {
  std::string mannequin;
  int rula_max = 0, reba_max = 0;
  std::array<double, 4> rula_time_s{};  ///< at RULA action level 1..4
  std::array<double, 5> reba_time_s{};  ///< at REBA action level 0..4
  long long samples = 0;
  long long failures = 0;  ///< postures the evaluator refused (non-finite q)
};

/// What a run measured (the --json keys).
struct Summary {
  long long frames = 0, steps = 0, nan_steps = 0, lcp_failures = 0, worlds = 0;
  double sim_time_s = 0, wall_s = 0;
  double max_penetration_m = 0;
  int max_contacts = 0;
  double contact_sum = 0;
  long long foot_contact_steps = 0;
  double min_balance_distance_m = kNaN;  // NaN: never a support polygon
  double min_force_margin_n = kNaN;      // NaN: never evaluated (physics.force_margin_period 0)
  double force_margin_sum = 0;
  long long force_margin_samples = 0;
  double worst_joint_limit_excess_rad = 0;
  double hand_error_sum = 0, foot_error_sum = 0;
  long long hand_samples = 0, foot_samples = 0;
  bool physics = false;
  std::vector<ErgonomicsSummary> ergonomics;

  double meanContacts() const { return steps > 0 ? contact_sum / static_cast<double>(steps) : 0.0; }
  double footContactFraction() const {
    return steps > 0 ? static_cast<double>(foot_contact_steps) / static_cast<double>(steps) : 0.0;
  }
  double meanHandError() const { return hand_samples > 0 ? hand_error_sum / static_cast<double>(hand_samples) : kNaN; }
  double meanFootError() const { return foot_samples > 0 ? foot_error_sum / static_cast<double>(foot_samples) : kNaN; }
  double realtimeFactor() const { return wall_s > 0 ? sim_time_s / wall_s : kNaN; }
  double meanForceMargin() const {
    return force_margin_samples > 0 ? force_margin_sum / static_cast<double>(force_margin_samples) : kNaN;
  }
};

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

/// After each step: the diagnostics into the summary (no allocation).
void accumulate(const sim::World& world, bool ok, Summary& s) {
  ++s.steps;
  const sim::StepDiagnostics& d = world.diagnostics();
  if (!ok || d.nan) ++s.nan_steps;
  if (world.physics()) {
    s.max_penetration_m = std::max(s.max_penetration_m, d.max_penetration_m);
    s.max_contacts = std::max(s.max_contacts, d.contacts);
    s.contact_sum += d.contacts;
  }
  bool foot = false;
  for (int m = 0; m < world.numMannequins(); ++m) {
    if (world.physics()) {
      const sim::MannequinDiagnostics& md = world.mannequinDiagnostics(m);
      foot = foot || md.foot_contact;
      if (std::isfinite(md.balance_distance_m) &&
          (!std::isfinite(s.min_balance_distance_m) || md.balance_distance_m < s.min_balance_distance_m))
        s.min_balance_distance_m = md.balance_distance_m;
      s.worst_joint_limit_excess_rad = std::max(s.worst_joint_limit_excess_rad, md.worst_joint_limit_excess_rad);
      if (std::isfinite(md.force_margin_n)) {
        if (!(md.force_margin_n >= s.min_force_margin_n)) s.min_force_margin_n = md.force_margin_n;  // NaN: the first
        s.force_margin_sum += md.force_margin_n;
        ++s.force_margin_samples;
      }
    }
    if (!world.calibrated(m)) continue;
    for (const sim::DrivenFrame& f : world.controlFrames(m)) {
      if (!f.tracked) continue;
      if (startsWith(f.frame, "hand_")) {
        s.hand_error_sum += f.position_error;
        ++s.hand_samples;
      } else if (startsWith(f.frame, "foot_")) {
        s.foot_error_sum += f.position_error;
        ++s.foot_samples;
      }
    }
  }
  if (foot) ++s.foot_contact_steps;
}

/// A JSON number (null when not finite). %.17g: the same double prints the same text.
std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : "null"; }

/// One sample of every calibrated mannequin's posture, weighing `dt` seconds.
void sampleErgonomics(const sim::World& world, std::vector<ergonomics::Evaluator>& evaluators, double dt, Summary& s) {
  for (int m = 0; m < world.numMannequins(); ++m) {
    if (!world.calibrated(m)) continue;
    ErgonomicsSummary& e = s.ergonomics[static_cast<std::size_t>(m)];
    try {
      const ergonomics::Assessment a = evaluators[static_cast<std::size_t>(m)].evaluate(world.q(m));
      const int rula = std::max(a.rula[0].grand, a.rula[1].grand), reba = std::max(a.reba[0].score, a.reba[1].score);
      e.rula_max = std::max(e.rula_max, rula);
      e.reba_max = std::max(e.reba_max, reba);
      e.rula_time_s[static_cast<std::size_t>(ergonomics::rulaActionLevel(rula) - 1)] += dt;
      e.reba_time_s[static_cast<std::size_t>(ergonomics::rebaActionLevel(reba))] += dt;
      ++e.samples;
    } catch (const std::invalid_argument&) {
      ++e.failures;
    }
  }
}

std::string ergonomicsJson(const Summary& s) {
  std::string out = "[";
  for (std::size_t i = 0; i < s.ergonomics.size(); ++i) {
    const ErgonomicsSummary& e = s.ergonomics[i];
    out += fmt::format("{}{{\"mannequin\": {}, \"samples\": {}, \"rula_max\": {}, \"rula_time_at_action_level_s\": [{}], "
                       "\"reba_max\": {}, \"reba_time_at_action_level_s\": [{}]}}",
                       i ? ", " : "", core::jsonString(e.mannequin), e.samples, e.rula_max, fmt::join(e.rula_time_s, ", "),
                       e.reba_max, fmt::join(e.reba_time_s, ", "));
  }
  return out + "]";
}

void printJson(const Summary& s) {
  std::printf(
      "{\"frames\": %lld, \"steps\": %lld, \"sim_time_s\": %s, \"wall_s\": %s, \"realtime_factor\": %s, "
      "\"physics\": %s, \"nan_steps\": %lld, \"lcp_failures\": %lld, \"max_penetration_m\": %s, \"max_contacts\": %d, "
      "\"mean_contacts\": %s, \"foot_contact_fraction\": %s, \"min_balance_distance_m\": %s, "
      "\"worst_joint_limit_excess_rad\": %s, \"min_force_margin_n\": %s, \"mean_force_margin_n\": %s, "
      "\"mean_hand_error_m\": %s, \"mean_foot_error_m\": %s, \"worlds\": %lld, \"ergonomics\": %s}\n",
      s.frames, s.steps, num(s.sim_time_s).c_str(), num(s.wall_s).c_str(), num(s.realtimeFactor()).c_str(),
      s.physics ? "true" : "false", s.nan_steps, s.lcp_failures, num(s.max_penetration_m).c_str(), s.max_contacts,
      num(s.meanContacts()).c_str(), num(s.footContactFraction()).c_str(), num(s.min_balance_distance_m).c_str(),
      num(s.worst_joint_limit_excess_rad).c_str(), num(s.min_force_margin_n).c_str(), num(s.meanForceMargin()).c_str(),
      num(s.meanHandError()).c_str(), num(s.meanFootError()).c_str(),
      s.worlds, ergonomicsJson(s).c_str());
}

void printHuman(const Summary& s, const std::string& out) {
  std::printf("simulated   %.3f s in %lld steps from %lld mocap frames, %.3f s wall (%.1fx real time)\n", s.sim_time_s,
              s.steps, s.frames, s.wall_s, s.realtimeFactor());
  std::printf("numerics    %lld NaN steps, %lld LCP failures (Lemke failed; fallback or none)\n", s.nan_steps, s.lcp_failures);
  if (s.physics) {
    std::printf("contacts    max %d, mean %.2f per step; max penetration %.2f mm\n", s.max_contacts, s.meanContacts(),
                s.max_penetration_m * 1e3);
    std::printf("feet        a foot on the floor %.1f %% of the steps\n", 100.0 * s.footContactFraction());
    if (std::isfinite(s.min_balance_distance_m))
      std::printf("balance     min distance %.4f m (signed, > 0: CoM projection inside the support)\n", s.min_balance_distance_m);
    else
      std::printf("balance     no balance distance reported by the World\n");
    if (std::isfinite(s.min_force_margin_n))
      std::printf("margin      the largest horizontal push at the CoM held: min %.1f N, mean %.1f N (0: not balanced)\n",
                  s.min_force_margin_n, s.meanForceMargin());
    else
      std::printf("margin      not evaluated (physics.force_margin_period: 0)\n");
    std::printf("limits      worst excess %.4f rad\n", s.worst_joint_limit_excess_rad);
  } else {
    std::printf("physics     off (sim config `physics: {enabled: true, scene: ...}` or --scene turns it on)\n");
  }
  std::printf("tracking    mean position error: hands %.1f mm, feet %.1f mm\n", s.meanHandError() * 1e3,
              s.meanFootError() * 1e3);
  for (const ErgonomicsSummary& e : s.ergonomics) {
    if (e.samples == 0) continue;
    std::printf("ergonomics  %s: RULA max %d, time at action levels 1-4: %.1f / %.1f / %.1f / %.1f s; REBA max %d, "
                "levels 0-4: %.1f / %.1f / %.1f / %.1f / %.1f s\n",
                e.mannequin.c_str(), e.rula_max, e.rula_time_s[0], e.rula_time_s[1], e.rula_time_s[2], e.rula_time_s[3],
                e.reba_max, e.reba_time_s[0], e.reba_time_s[1], e.reba_time_s[2], e.reba_time_s[3], e.reba_time_s[4]);
  }
  if (!out.empty()) std::printf("wrote       %lld sim.world messages to %s\n", s.worlds, out.c_str());
}

/// A progress bar on stderr, redrawn at most every 0.1 s.
class Progress {
 public:
  Progress(bool on, double total) : on_(on), total_(total) {}
  void update(double sim_time, double wall) {
    if (!on_ || wall - last_ < 0.1) return;
    last_ = wall;
    const double f = total_ > 0 ? std::min(1.0, sim_time / total_) : 0.0;
    const int width = 30, filled = static_cast<int>(f * width);
    std::fprintf(stderr, "\r[%s%s] %5.1f%%  %.2f / %.2f s  %.1fx real time ", std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), 100 * f, sim_time, total_, wall > 0 ? sim_time / wall : 0.0);
    std::fflush(stderr);
  }
  void done() {
    if (on_) std::fprintf(stderr, "\r%*s\r", 80, "");
  }

 private:
  bool on_;
  double total_, last_ = -1.0;
};

/// Everything read from files before the run (each failure a FILE:LINE message).
struct Setup {
  simservice::SimServiceConfig config;
  std::unique_ptr<mocap::Source> source;
  double capture_length_s = 0;  ///< the BVH's length (s), for the progress bar
  std::unique_ptr<sim::World> world;
};

Setup load(const std::string& config_path, const std::string& mocap_bvh, const std::string& mannequin,
           const std::string& scene) {
  Setup s;
  s.config = simservice::loadSimConfig(core::findData(config_path));
  simservice::SimServiceConfig& c = s.config;
  c.world.interpolation_delay = 0.0;  // frames fed up to each capture time (replay semantics)
  c.mode = simservice::Mode::kReplay;
  if (!mannequin.empty())
    for (simservice::MannequinEntry& e : c.mannequins) {
      e.config = core::findData(mannequin);
      e.where.clear();
    }
  if (!scene.empty()) {
    c.world.physics.scene = collision::loadScene(core::findData(scene));
    c.world.physics.enabled = true;
  }
  if (c.collision.mode == simservice::CollisionMode::kService)
    spdlog::info("collision: mode service needs mannequin-collision on the network: not used here{}",
                 c.world.physics.enabled ? " (the physics queries its own collision world)" : "");

  // the capture: the sim config's `mocap` (a mocap service config), --mocap replacing its BVH file
  const std::string mocap_path = c.mocap.empty() ? core::findData("configs/sim/mocap_demo.yaml") : c.mocap;
  YAML::Node raw;
  try {
    raw = YAML::LoadFile(mocap_path);
  } catch (const YAML::Exception& e) {
    throw core::ConfigError(fmt::format("{}:{}: {}", mocap_path, e.mark.line + 1, e.msg));
  }
  if (!raw.IsMap()) throw core::ConfigError(mocap_path + ":1: a mocap config (a map with `source: bvh` and a `bvh` section)");
  if (!raw["source"] || raw["source"].as<std::string>("") != "bvh" || !raw["bvh"]) {
    const YAML::Mark at = raw["source"] ? raw["source"].Mark() : raw.Mark();
    throw core::ConfigError(fmt::format("{}:{}: field 'source': mannequin-simulate plays BVH captures (source: bvh with a bvh section)",
                                        mocap_path, at.line + 1));
  }
  if (!mocap_bvh.empty()) raw["bvh"]["file"] = mocap_bvh;
  raw["bvh"]["loop"] = false;   // the capture once
  raw["bvh"]["paced"] = false;  // as fast as asked for
  s.source = mocap::makeSource(core::ConfigNode(raw, mocap_path));
  if (const auto* b = dynamic_cast<const mocap::BvhSource*>(s.source.get()))
    s.capture_length_s = b->bvh().num_frames * b->bvh().frame_time / raw["bvh"]["rate"].as<double>(1.0);
  s.world = std::make_unique<sim::World>(simservice::buildMannequins(c), c.world);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-simulate: the sim service's World in one process, no network. Feeds a capture's frames at\n"
               "their capture times and steps as fast as possible (deterministic), then prints a summary."};
  std::string config_path = "configs/sim/sim_demo.yaml", mocap_bvh, mannequin, scene, out, log_level = "warn";
  double duration = -1;
  bool json = false;
  app.add_option("--config,-c", config_path, "sim config (configs/sim/sim_*.yaml)")->capture_default_str();
  app.add_option("--mocap", mocap_bvh, "BVH capture replacing the file of the sim config's `mocap` config "
                                       "(its map and bodies are kept)");
  app.add_option("--mannequin", mannequin, "mannequin config (configs/mannequins/*.yaml) for every mannequin");
  app.add_option("--scene", scene, "scene file (configs/scenes/*.yaml): turns the physics on with this scene");
  app.add_option("--duration", duration, "seconds of simulation (default: the whole capture)")->check(CLI::PositiveNumber);
  app.add_option("--out,-o", out, "MCAP file of the sim.world messages (at the config's world_rate)");
  app.add_flag("--json", json, "print exactly one JSON object on stdout");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")->capture_default_str()->check(core::logLevelCheck());
  return core::runMain(app, argc, argv, [&]() -> int {
    core::setupLogging(log_level);
    Setup setup;
    try {
      setup = load(config_path, mocap_bvh, mannequin, scene);
    } catch (const std::exception& e) {  // a bad file: its FILE:LINE message, exit 2 (as a bad command line)
      std::fprintf(stderr, "mannequin-simulate: %s\n", e.what());
      return core::kExitUsage;
    }
    const simservice::SimServiceConfig& config = setup.config;
    sim::World& world = *setup.world;
    Summary s;
    s.physics = world.physics();
    std::vector<ergonomics::Evaluator> evaluators;
    for (int m = 0; m < world.numMannequins(); ++m) {
      s.ergonomics.push_back({world.name(m)});
      try {
        evaluators.emplace_back(world.model(m));
      } catch (const std::invalid_argument& e) {  // a model without the mannequin's joints (not buildMannequin's)
        std::fprintf(stderr, "mannequin-simulate: %s: no ergonomic scores: %s\n", world.name(m).c_str(), e.what());
        return core::kExitUsage;
      }
    }

    std::unique_ptr<recording::McapWriter> writer;
    std::uint16_t channel = 0;
    if (!out.empty()) {
      writer = std::make_unique<recording::McapWriter>(out);
      const std::uint16_t schema = writer->addSchema("mannequin.v1.WorldState", "protobuf",
                                                     proto::fileDescriptorSet(v1::WorldState::descriptor()));
      channel = writer->addChannel(std::string(transport::topics::kSimWorld.name), schema, "protobuf");
    }
    v1::WorldState msg;
    std::string payload;
    double world_phase = 0.0;
    const auto publish = [&] {
      world_phase += config.world_rate * config.world.step;
      if (world_phase < 1.0 - 1e-9) return;
      world_phase -= 1.0;
      sampleErgonomics(world, evaluators, 1.0 / config.world_rate, s);
      if (!writer) return;
      simservice::toWorldState(world, nullptr, false, true, msg);
      v1::Header* h = msg.mutable_header();
      h->set_schema_version(transport::kSchemaVersion);
      h->set_sequence(static_cast<std::uint64_t>(++s.worlds));
      h->set_source(config.name);
      h->set_send_time_ns(0);  // deterministic
      msg.SerializeToString(&payload);
      const auto t = static_cast<recording::Timestamp>(h->stamp_ns());
      writer->write(channel, static_cast<std::uint32_t>(s.worlds), t, t, payload);
    };

    const double total = duration > 0 ? duration : std::numeric_limits<double>::infinity();
    const std::int64_t step_ns = std::llround(config.world.step * 1e9);
    Progress progress(::isatty(STDERR_FILENO) == 1, std::isfinite(total) ? total : setup.capture_length_s);
    const auto t0 = std::chrono::steady_clock::now();
    const auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    const std::vector<std::string> sources = world.mocapSources();  // "" first
    bool done = false;
    while (!done && !setup.source->finished()) {
      const std::optional<mocap::Frame> f = setup.source->next(std::chrono::microseconds(0));
      if (!f) continue;
      ++s.frames;
      // the one capture drives every mocap source the mannequins name (sim config `mocap_sources`)
      for (const std::string& src : sources) {
        world.addMocap(*f, src);
        if (!world.anchored(src)) world.anchor(f->stamp_ns, src);
      }
      while (world.captureTimeNs(sources.front()) + step_ns <= f->stamp_ns) {
        if (world.time() + 0.5 * config.world.step >= total) {
          done = true;
          break;
        }
        const bool ok = world.step();
        accumulate(world, ok, s);
        publish();
        progress.update(world.time(), wall());
      }
    }
    s.wall_s = wall();
    progress.done();
    s.sim_time_s = world.time();
    if (const constraints::ConstraintSolver* cs = world.constraintSolver()) s.lcp_failures = cs->failures();
    if (writer) writer->close();
    if (json)
      printJson(s);
    else
      printHuman(s, out);
    return core::kExitOk;
  });
}
