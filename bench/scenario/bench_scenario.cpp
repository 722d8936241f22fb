// bench-scenario: the cost of the scenario's state machine in the 1 kHz loop (scenario::Engine::step):
// 10 control frames (free, autonomous and constrained modes), 20 transitions per state whose events mix
// zones, distances, forces, object values, triggers, `reached` and boolean combinations, evaluated every
// step. BM_ScenarioStep/switch_every_steps:0 never switches (the evaluation alone);
// /switch_every_steps:N switches state every N steps (configure, start, teardown, a minimum-jerk
// trajectory and blends built at each switch). Goal (issue 17): ≤ 5 µs per step.
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "bench_main.hpp"
#include "mannequin/scenario/engine.hpp"

using namespace mannequin;

namespace {

constexpr int kFrames = 10;
constexpr int kTransitions = 20;

// Two states, s0 and s1, each with the same 20 transitions to the other: 19 that do not fire in this
// run (zones and thresholds out of reach) and one on the time in state (`switch_s`; never when 0).
std::string scenarioText(double switch_s) {
  std::string frames, modes;
  for (int f = 0; f < kFrames; ++f) frames += fmt::format("{}f{}", f ? ", " : "", f);
  for (int f = 0; f < kFrames; ++f) {
    if (f == 1)
      modes += "      f1: {mode: autonomous, goal: {xyz: [0.4, -0.2, 1.2], rpy_deg: [0, 0, 0]}, duration_s: 0.05}\n";
    else if (f == 2)
      modes += "      f2: {mode: constrained, mechanism: {type: prismatic, origin: {xyz: [0.3, 0.1, 1.0], rpy_deg: [0, 90, 0]}, "
               "limits: [[-0.5, 0.5]]}}\n";
    else
      modes += fmt::format("      f{}: free\n", f);
  }
  std::string transitions;
  for (int k = 0; k < kTransitions - 1; ++k) {
    const int f = k % kFrames;
    std::string when;
    switch (k % 7) {
      case 0: when = fmt::format("{{enter: {{frame: f{}, sphere: {{center: [5, 5, 5], radius: 0.1}}}}}}", f); break;
      case 1: when = fmt::format("{{inside: {{frame: f{}, box: {{center: [-5, 0, 1], half_extents: [0.2, 0.2, 0.2], rpy_deg: [0, 0, 30]}}}}}}", f); break;
      case 2: when = fmt::format("{{distance: {{frame: f{}, to_frame: f{}, below: 0.0001}}}}", f, (f + 1) % kFrames); break;
      case 3: when = fmt::format("{{all: [{{force: {{frame: f{}, above: 500}}}}, {{time: 0.01}}]}}", f); break;
      case 4: when = "{object: {name: door, value: angle, above: 3.0}}"; break;
      case 5: when = "{any: [{trigger: go}, {not: {time: 0.0}}]}"; break;
      default: when = fmt::format("{{reached: {{frame: f{}, pose: {{xyz: [9, 9, 9], rpy_deg: [0, 0, 0]}}, tolerance_m: 0.01}}}}", f); break;
    }
    transitions += fmt::format("      - {{to: @, name: t{}, when: {}}}\n", k, when);
  }
  transitions += fmt::format("      - {{to: @, name: timed, when: {{time: {}}}}}\n", switch_s > 0 ? switch_s : 1e9);
  std::string states;
  for (int s = 0; s < 2; ++s) {
    std::string t = transitions;
    for (std::size_t p; (p = t.find('@')) != std::string::npos;) t.replace(p, 1, s == 0 ? "s1" : "s0");
    states += fmt::format("  - name: s{}\n    modes:\n{}    transitions:\n{}", s, modes, t);
  }
  return fmt::format("scenario: bench\nmannequins:\n  - name: m\n    frames: [{}]\nobjects:\n  - name: door\n    values: [angle]\n"
                     "triggers: [go]\ninitial: s0\nstates:\n{}",
                     frames, states);
}

void BM_ScenarioStep(benchmark::State& state) {
  const long every = state.range(0);
  const double dt = 1e-3;
  scenario::Engine engine(scenario::parseScenario(scenarioText(every > 0 ? (static_cast<double>(every) - 0.5) * dt : 0.0), "bench.yaml"));
  scenario::Observation obs;
  obs.frames.resize(kFrames);
  obs.objects.resize(1);
  obs.objects[0].values.assign(1, 0.0);
  for (int f = 0; f < kFrames; ++f) {
    auto& o = obs.frames[static_cast<std::size_t>(f)];
    o.pose.p = math::Vector3(0.1 * f, 0.05 * f, 1.0);
    o.target = o.pose;
  }
  long k = 0, switches = 0;
  for (auto _ : state) {
    obs.time = static_cast<double>(k) * dt;
    for (int f = 0; f < kFrames; ++f) {  // the actor moves: targets on small circles
      auto& o = obs.frames[static_cast<std::size_t>(f)];
      o.target.p.x() = 0.1 * f + 0.05 * std::cos(obs.time + f);
      o.target.p.y() = 0.05 * f + 0.05 * std::sin(obs.time + f);
    }
    const scenario::StepResult& r = engine.step(obs);
    for (int f = 0; f < kFrames; ++f) obs.frames[static_cast<std::size_t>(f)].pose = r.frames[static_cast<std::size_t>(f)].setpoint.pose;
    switches += r.switched ? 1 : 0;
    benchmark::DoNotOptimize(r.frames.data());
    ++k;
  }
  state.counters["switches"] = static_cast<double>(switches);
  state.counters["frames"] = kFrames;
  state.counters["transitions_per_state"] = kTransitions;
}
BENCHMARK(BM_ScenarioStep)->ArgName("switch_every_steps")->Arg(0)->Arg(100)->Arg(10)->Unit(benchmark::kMicrosecond);

}  // namespace

MANNEQUIN_BENCHMARK_MAIN("bench-scenario")
