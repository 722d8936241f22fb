// mannequin-simulate: the sim service's World in one process, without the network: a capture's frames
// fed at their capture times, the World stepped as fast as possible (deterministic, like the service's
// replay mode), a summary of the run (human or --json), optionally the sim.world messages in an MCAP file
// (the v1 messages mannequin-record writes; mannequin-replay reads it). See docs/cluster.md.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "mannequin/core/main.hpp"
#include "mannequin/core/text.hpp"
#include "mannequin/simservice/offline.hpp"

using namespace mannequin;

namespace {

using Summary = simservice::OfflineSummary;
using simservice::ErgonomicsSummary;

/// A JSON number (null when not finite). %.17g: the same double prints the same text.
std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : "null"; }

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

std::string kineticsJson(const Summary& s) {
  std::string out = "[";
  for (std::size_t i = 0; i < s.kinetics.size(); ++i) out += (i ? ", " : "") + simservice::kineticsJson(s.kinetics[i]);
  return out + "]";
}

std::string scenarioJson(const Summary& s) {
  if (s.scenario.empty()) return "null";
  std::string timeline;
  for (const Summary::ScenarioEntry& e : s.scenario_timeline)
    timeline += fmt::format("{}{{\"t\": {}, \"state\": {}, \"events\": {}}}", timeline.empty() ? "" : ", ", num(e.t),
                            core::jsonString(e.state), core::jsonString(e.events));
  return fmt::format("{{\"name\": {}, \"final_state\": {}, \"states\": {}, \"triggers_sent\": {}, "
                     "\"unapplied_actions\": {}, \"timeline\": [{}]}}",
                     core::jsonString(s.scenario), core::jsonString(s.scenario_state), s.scenario_states, s.scenario_triggers,
                     s.scenario_unapplied_actions, timeline);
}

void printJson(const Summary& s) {
  std::printf(
      "{%s, \"physics\": %s, \"worst_joint_limit_excess_rad\": %s, \"mean_force_margin_n\": %s, "
      "\"balance_controller\": {\"enabled\": %s, \"solves\": %lld, \"failures\": %lld, \"driving_fraction\": %s, "
      "\"full_margin_fraction\": %s}, "
      "\"mean_hand_error_m\": %s, \"mean_foot_error_m\": %s, \"worlds\": %lld, \"ergonomics\": %s, \"kinetics\": %s, "
      "\"scenario\": %s}\n",
      simservice::summaryJsonMembers(s).c_str(), s.physics ? "true" : "false", num(s.worst_joint_limit_excess_rad).c_str(),
      num(s.meanForceMargin()).c_str(), s.balance_controller ? "true" : "false", s.balance_solves, s.balance_failures,
      num(s.balanceDrivingFraction()).c_str(), num(s.balanceFullMarginFraction()).c_str(), num(s.meanHandError()).c_str(),
      num(s.meanFootError()).c_str(), s.worlds, ergonomicsJson(s).c_str(), kineticsJson(s).c_str(), scenarioJson(s).c_str());
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
    if (s.balance_controller)
      std::printf("controller  balance (Alg. 5) drove %.1f %% of the mannequin-steps, the whole margin held in %.1f %% of them; "
                  "%lld solves, %lld failed updates\n",
                  100.0 * s.balanceDrivingFraction(), 100.0 * s.balanceFullMarginFraction(), s.balance_solves, s.balance_failures);
    std::printf("limits      worst excess %.4f rad\n", s.worst_joint_limit_excess_rad);
    for (const sim::MannequinKinetics& mk : s.kinetics) {
      const kinetics::KineticsSummary& k = mk.summary;
      if (k.frames == 0) continue;
      std::printf("kinetics    %s: ground reaction %.3f x weight (%.0f N) on average, peak %.0f N; residual force mean "
                  "%.1f N, peak %.1f N; residual moment peak %.1f N m\n",
                  mk.mannequin.c_str(), k.grf_mean_over_weight, k.weight_n, k.peak_external_force_n, k.residual_force_mean_n,
                  k.residual_force_peak_n, k.residual_moment_peak_nm);
    }
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
  if (!s.scenario.empty()) {
    std::printf("scenario    %s: %zu state change(s), %lld trigger(s) sent, ends in '%s'%s\n", s.scenario.c_str(),
                s.scenario_timeline.empty() ? 0 : s.scenario_timeline.size() - 1, s.scenario_triggers,
                s.scenario_state.empty() ? "(never ran: mannequins not calibrated)" : s.scenario_state.c_str(),
                s.scenario_unapplied_actions > 0 ? fmt::format("; {} action(s) not applied by the World yet",
                                                               s.scenario_unapplied_actions).c_str() : "");
    for (const Summary::ScenarioEntry& e : s.scenario_timeline)
      std::printf("            %8.3f s  %s%s\n", e.t, e.state.c_str(), e.events.empty() ? "" : ("  <- " + e.events).c_str());
  }
  if (!out.empty()) std::printf("wrote       %lld sim.world messages to %s\n", s.worlds, out.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-simulate: the sim service's World in one process, no network. Feeds a capture's frames at\n"
               "their capture times and steps as fast as possible (deterministic), then prints a summary."};
  std::string config_path = "configs/sim/sim_demo.yaml", mocap_bvh, mannequin, scene, scenario, out, log_level = "warn";
  double duration = -1;
  bool json = false;
  app.add_option("--config,-c", config_path, "sim config (configs/sim/sim_*.yaml)")->capture_default_str();
  app.add_option("--mocap", mocap_bvh, "capture replacing the sim config's: a BVH file (the `mocap` config's map and "
                                       "bodies kept), a .c3d or an .mcap recording (its mocap.frame messages)");
  app.add_option("--mannequin", mannequin, "mannequin config (configs/mannequins/*.yaml) for every mannequin");
  app.add_option("--scene", scene, "scene file (configs/scenes/*.yaml): turns the physics on with this scene");
  app.add_option("--scenario", scenario, "scenario file (configs/scenarios/*.yaml) run in the loop, replacing the sim "
                                         "config's `scenario` (docs/scenario.md)");
  app.add_option("--duration", duration, "seconds of simulation (default: the whole capture)")->check(CLI::PositiveNumber);
  app.add_option("--out,-o", out, "MCAP file of the sim.world messages (at the config's world_rate)");
  app.add_flag("--json", json, "print exactly one JSON object on stdout");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")->capture_default_str()->check(core::logLevelCheck());
  return core::runMain(app, argc, argv, [&]() -> int {
    core::setupLogging(log_level);
    simservice::OfflineOptions options;
    options.config = config_path;
    options.mocap = mocap_bvh;
    options.mannequin = mannequin;
    options.scene = scene;
    options.scenario = scenario;
    options.duration = duration;
    options.out = out;
    options.progress = ::isatty(STDERR_FILENO) == 1;
    Summary s;
    try {  // a bad file: its FILE:LINE message, exit 2 (as a bad command line)
      simservice::OfflineRun run(options);
      s = run.run();
    } catch (const simservice::OfflineInputError& e) {
      std::fprintf(stderr, "mannequin-simulate: %s\n", e.what());
      return core::kExitUsage;
    }
    if (json)
      printJson(s);
    else
      printHuman(s, out);
    return core::kExitOk;
  });
}
