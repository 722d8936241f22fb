// bench-control: one step of the control core (thesis Alg. 2 with priorities) on the male_50th
// mannequin: 43 velocity DoF (6 root + 37 internal), 6 control frames (feet, pelvis at level 0;
// hands, head at level 1), internal control projected in ker(J b_a⁻¹), gravity. Rows:
//   BM_ControlStep/ldlt      the whole step (configs/control/default.yaml), goal < 50 µs
//   BM_ControlStep/svd       the same with the SVD-based projectors (thesis 1.41)
//   BM_FreeMotion            stage 1 only (what runs before the constraint solver)
//   BM_Projector*            one 36-row b_a-weighted projector: LDLᵀ of J b_a⁻¹ Jᵀ vs JacobiSVD of J b_a^{-1/2}
//   BM_ControlStepMechanism  with a sliding-pivot virtual mechanism on the right hand
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

#include "bench_main.hpp"
#include "mannequin/control/controller.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

using namespace mannequin;
using namespace mannequin::control;

namespace {
const skeleton::Model& model() {
  static const skeleton::Model m =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  return m;
}
ControllerConfig config(ProjectorMethod method) {
  ControllerConfig c = loadControllerConfig(mannequin::bench::dataFile("configs/control/default.yaml"));
  c.projector = method;
  return c;
}

// moving hand targets so that every step does real work
void stepLoop(benchmark::State& state, Controller& ctl) {
  const int hl = ctl.frameIndex("hand_l"), hr = ctl.frameIndex("hand_r");
  const SE3 l0 = ctl.frame(hl).pose, r0 = ctl.frame(hr).pose;
  long i = 0;
  for (auto _ : state) {
    const double t = 1e-3 * static_cast<double>(i++ % 4000);
    SE3 l = l0, r = r0;
    l.p += Vector3(0.15 * std::sin(t), 0.0, 0.2 * (1 - std::cos(t)));
    r.p += Vector3(0.2 * (1 - std::cos(t)), 0.0, 0.15 * std::sin(t));
    ctl.setTarget(hl, l);
    ctl.setTarget(hr, r);
    benchmark::DoNotOptimize(ctl.step());
  }
  state.counters["nv"] = ctl.model().nv;
  state.counters["frames"] = ctl.numFrames();
}
}  // namespace

static void BM_ControlStep(benchmark::State& state) {
  const auto method = state.range(0) == 0 ? ProjectorMethod::kLdlt : ProjectorMethod::kSvd;
  Controller ctl(model(), config(method));
  state.SetLabel(toString(method));
  stepLoop(state, ctl);
}
BENCHMARK(BM_ControlStep)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

static void BM_ControlStepMechanism(benchmark::State& state) {
  Controller ctl(model(), config(ProjectorMethod::kLdlt));
  const int h = ctl.frameIndex("hand_r");
  MechanismConfig m;
  m.spec.type = MechanismType::kSlidingPivot;
  m.spec.base = ctl.frame(h).pose;
  m.stiffness << 1000, 1000, 1000, 10000, 10000, 10000;
  m.damping = m.stiffness * 1e-2;
  m.enabled = true;
  ctl.attachMechanism(h, m);
  stepLoop(state, ctl);
}
BENCHMARK(BM_ControlStepMechanism)->Unit(benchmark::kMicrosecond);

static void BM_FreeMotion(benchmark::State& state) {
  Controller ctl(model(), config(ProjectorMethod::kLdlt));
  for (auto _ : state) benchmark::DoNotOptimize(ctl.computeFreeMotion());
}
BENCHMARK(BM_FreeMotion)->Unit(benchmark::kMicrosecond);

static void BM_Projector(benchmark::State& state) {
  const auto method = state.range(0) == 0 ? ProjectorMethod::kLdlt : ProjectorMethod::kSvd;
  Controller ctl(model(), config(method));
  ctl.computeFreeMotion();
  const MatrixX J = ctl.taskJacobian();
  const VectorX w_inv = ctl.frictionDiagonal().cwiseInverse();
  WeightedNullSpace p(static_cast<int>(J.rows()), static_cast<int>(J.cols()), method, 1e-9);
  VectorX g = VectorX::Ones(J.cols()), out(J.cols());
  for (auto _ : state) {
    p.compute(J, w_inv);
    p.projectTorque(g, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetLabel(std::string(toString(method)) + " rows=" + std::to_string(J.rows()) + " rank=" + std::to_string(p.rank()));
}
BENCHMARK(BM_Projector)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

MANNEQUIN_BENCHMARK_MAIN("bench-control", "configs/mannequins/male_50th.yaml", "configs/control/default.yaml")
