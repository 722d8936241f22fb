// bench-ik: cost of the priority loop, recursive projector (paper eq. 8, O(p)) against the full
// recomputation (eq. 7, Siciliano–Slotine, O(p²)), reproducing paper Fig. 5: a 50-DoF chain,
// each level a 5-D constraint, p = 1..10. Also one IK step and one solve on the mannequin.
// The console run ends with the Fig. 5 table and the ratio (7)/(8) per p.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <string>

#include "bench_main.hpp"
#include "mannequin/ik/solver.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

using namespace mannequin;
using namespace mannequin::ik;

namespace {

std::vector<LinearLevel> fig5Levels(int p) {
  std::mt19937 g(42);
  std::normal_distribution<double> nd;
  std::vector<LinearLevel> levels;
  for (int k = 0; k < p; ++k) {
    LinearLevel L{MatrixX(5, 50), VectorX(5), 0.01};
    for (int i = 0; i < 5; ++i) {
      L.dx(i) = nd(g);
      for (int j = 0; j < 50; ++j) L.J(i, j) = nd(g);
    }
    levels.push_back(std::move(L));
  }
  return levels;
}

void BM_PriorityLoop(benchmark::State& state) {
  const bool full = state.range(0) == 1;
  const int p = static_cast<int>(state.range(1));
  const auto levels = fig5Levels(p);
  PriorityLoop loop(50, {full ? ProjectorUpdate::kFull : ProjectorUpdate::kRecursive, 1e-9});
  for (auto _ : state) benchmark::DoNotOptimize(loop.solve(levels).data());
  state.SetLabel(full ? "eq7_full" : "eq8_recursive");
}
BENCHMARK(BM_PriorityLoop)->ArgsProduct({{0, 1}, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10}})->ArgNames({"full", "p"})
    ->Unit(benchmark::kMicrosecond);


struct Mannequin {
  skeleton::Model model =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(mannequin::bench::dataFile("configs/mannequins/male_50th.yaml")));
  VectorX q0 = skeleton::standingConfiguration(model);
};

// Retargeting-like levels: feet 6D, pelvis 6D, hands 6D, head orientation + posture.
void addRetargetLevels(IkSolver& s, const skeleton::Model& m, const VectorX& q0) {
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, q0);
  auto pose = [&](const char* f) {
    SE3 H = d.oMf[m.frameIndex(f)];
    H.p += Vector3(0.05, 0.02, -0.03);
    return H;
  };
  s.addLevel({"feet", 0.0, 1e-4});
  s.emplaceTask<FrameTask>(0, m, "foot_l").setTarget(d.oMf[m.frameIndex("foot_l")]);
  s.emplaceTask<FrameTask>(0, m, "foot_r").setTarget(d.oMf[m.frameIndex("foot_r")]);
  s.addLevel({"pelvis", 0.01, 1e-3});
  s.emplaceTask<FrameTask>(1, m, "pelvis").setTarget(pose("pelvis"));
  s.addLevel({"hands", 0.02, 1e-3});
  s.emplaceTask<FrameTask>(2, m, "hand_l").setTarget(pose("hand_l"));
  s.emplaceTask<FrameTask>(2, m, "hand_r").setTarget(pose("hand_r"));
  s.addLevel({"head+posture", 0.05, 1e9});
  s.emplaceTask<FrameTask>(3, m, "head", "", "xyz").setTarget(d.oMf[m.frameIndex("head")]);
  s.emplaceTask<PostureTask>(3, m, q0);
}

void BM_MannequinStep(benchmark::State& state) {
  static Mannequin mq;
  SolverOptions o;
  o.update = state.range(0) == 1 ? ProjectorUpdate::kFull : ProjectorUpdate::kRecursive;
  IkSolver s(mq.model, o);
  addRetargetLevels(s, mq.model, mq.q0);
  for (auto _ : state) benchmark::DoNotOptimize(s.step(mq.q0).data());
  state.SetLabel(std::string("43 DoF, 4 levels, 37 rows, ") + (state.range(0) ? "eq7_full" : "eq8_recursive"));
}
BENCHMARK(BM_MannequinStep)->Arg(0)->Arg(1)->ArgName("full")->Unit(benchmark::kMicrosecond);

void BM_MannequinSolve(benchmark::State& state) {
  static Mannequin mq;
  IkSolver s(mq.model);
  addRetargetLevels(s, mq.model, mq.q0);
  int iterations = 0;
  for (auto _ : state) {
    VectorX q = mq.q0;
    iterations = s.solve(q).iterations;
    benchmark::DoNotOptimize(q.data());
  }
  state.counters["iterations"] = iterations;
  state.SetLabel("5 cm / 3 cm target offsets from standing, to tolerance");
}
BENCHMARK(BM_MannequinSolve)->Unit(benchmark::kMicrosecond);

// Console reporter that also prints the Fig. 5 table at the end.
class Fig5Reporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      const std::string name = r.benchmark_name();
      if (name.rfind("BM_PriorityLoop/", 0) != 0 || r.run_type != Run::RT_Iteration) continue;
      const bool full = name.find("full:1") != std::string::npos;
      const int p = std::atoi(name.substr(name.find("p:") + 2).c_str());
      (full ? full_ : rec_)[p] = r.GetAdjustedRealTime();
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    if (rec_.empty()) return;
    std::printf("\nPaper Fig. 5: 50 DoF, 5-D levels, time per priority loop (us)\n");
    std::printf("%3s %14s %14s %12s\n", "p", "(8) recursive", "(7) full", "(7)/(8)");
    for (const auto& [p, t8] : rec_) {
      const auto it = full_.find(p);
      if (it == full_.end()) continue;
      std::printf("%3d %14.2f %14.2f %12.2f\n", p, t8, it->second, it->second / t8);
    }
  }

 private:
  std::map<int, double> rec_, full_;
};

}  // namespace

int main(int argc, char** argv) {
  bool console = true;  // (read before Initialize, which consumes the flags)
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--benchmark_format=", 19) == 0 && std::strcmp(argv[i] + 19, "console") != 0) console = false;
  return mannequin::bench::guarded("bench-ik", [&] {
    mannequin::bench::requireData({"configs/mannequins/male_50th.yaml"});
    Fig5Reporter reporter;
    return mannequin::bench::runSpecified(argc, argv, console ? &reporter : nullptr);
  });
}
