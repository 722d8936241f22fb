// bench-step: one step of the sim's World for the male_50th mannequin driven by the demo's six mocap
// bodies (pelvis, head, hands, feet), a new 120 Hz mocap frame every 8 or 9 steps of 1 ms, the hands
// moving on circles (0.2 m radius, 1 rev/s ≈ 1.3 m/s) and the pelvis swaying. Rows:
//   BM_WorldStep/controller   the ControllerStepper (configs/control/mocap.yaml, as the demo)
//   BM_WorldStep/controller_no_target_twist   the same without the targets' velocities fed forward
//   BM_WorldStep/kinematic    the KinematicTracker (damped least squares, SVD of the 36×43 Jacobian)
// Counters: hand_err_mm / pelvis_err_mm, the mean position error of the left hand and the pelvis over
// the run (how well each stepper follows the same motion), and the frame count.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "bench_main.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/sim/world.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

using namespace mannequin;
using namespace mannequin::sim;

namespace {

const char* kBodies[] = {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r"};

void worldStep(benchmark::State& state, bool controller, bool feed_forward) {
  MannequinSetup m;
  m.name = "operator";
  m.model = skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  for (const char* b : kBodies) m.frames.push_back({b, b});
  if (controller) m.controller = control::loadControllerConfig(mannequin::bench::dataFile("configs/control/mocap.yaml"));
  skeleton::Data d(m.model);
  skeleton::forwardKinematics(m.model, d, skeleton::standingConfiguration(m.model));
  std::vector<math::SE3> rest;
  for (const char* b : kBodies) rest.push_back(d.oMf[m.model.frameIndex(b)]);
  std::vector<MannequinSetup> setups;
  setups.push_back(std::move(m));
  SimConfig cfg;
  cfg.target_twist = feed_forward;
  World w(std::move(setups), cfg);
  auto frameAt = [&](std::int64_t stamp_ns) {
    const double t = static_cast<double>(stamp_ns) * 1e-9, a = 2 * M_PI * t;
    mocap::Frame f;
    f.stamp_ns = stamp_ns;
    for (int i = 0; i < 6; ++i) {
      math::SE3 H = rest[i];
      if (i == 0) H.p += math::Vector3(0.03 * std::sin(a / 2), 0.03 * std::sin(a / 3), 0);
      if (i == 2) H.p += math::Vector3(0.2 * std::sin(a), 0, 0.2 * (1 - std::cos(a)));
      if (i == 3) H.p += math::Vector3(0.2 * (1 - std::cos(a)), 0, 0.2 * std::sin(a));
      f.bodies.push_back({kBodies[i], H, true});
    }
    return f;
  };
  w.addMocap(frameAt(0));
  w.anchor(0);
  std::int64_t next_frame = 0;
  double hand_err = 0, pelvis_err = 0;
  long n = 0;
  for (auto _ : state) {
    if (w.captureTimeNs() >= next_frame) {  // 120 Hz capture
      next_frame += 8'333'333;
      w.addMocap(frameAt(next_frame));
    }
    benchmark::DoNotOptimize(w.step());
    pelvis_err += w.controlFrames(0)[0].position_error;
    hand_err += w.controlFrames(0)[2].position_error;
    ++n;
  }
  state.SetLabel(std::string(w.stepper(0).kind()));
  state.counters["hand_err_mm"] = n ? 1e3 * hand_err / static_cast<double>(n) : 0.0;
  state.counters["pelvis_err_mm"] = n ? 1e3 * pelvis_err / static_cast<double>(n) : 0.0;
  state.counters["failed_steps"] = static_cast<double>(w.failedSteps());
}
}  // namespace

static void BM_WorldStep(benchmark::State& state, bool controller, bool feed_forward) {
  worldStep(state, controller, feed_forward);
}
BENCHMARK_CAPTURE(BM_WorldStep, controller, true, true)->Unit(benchmark::kMicrosecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_WorldStep, controller_no_target_twist, true, false)->Unit(benchmark::kMicrosecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_WorldStep, kinematic, false, false)->Unit(benchmark::kMicrosecond)->MinTime(2.0);

MANNEQUIN_BENCHMARK_MAIN("bench-step", "configs/mannequins/male_50th.yaml", "configs/control/mocap.yaml")
