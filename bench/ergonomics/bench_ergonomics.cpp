// bench-ergonomics: the ergonomic scoring of one posture of the 50th-percentile male (issue 18 goal:
// RULA + REBA ≤ 2 µs per frame): the angles (forward kinematics included) and both sides' RULA and REBA,
// and the scoring alone from measured angles, on postures of a reach (shoulder, elbow, trunk flexed).
#include <vector>

#include "bench_main.hpp"
#include "mannequin/ergonomics/ergonomics.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin;

namespace {

const skeleton::Model& model() {
  static const skeleton::Model m =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(bench::dataFile("configs/mannequins/male_50th.yaml")));
  return m;
}

/// 16 postures between standing and a forward reach with the trunk flexed (every coordinate moved).
std::vector<skeleton::VectorX> postures() {
  const skeleton::Model& m = model();
  const skeleton::VectorX q0 = skeleton::standingConfiguration(m);
  std::vector<skeleton::VectorX> out;
  for (int k = 0; k < 16; ++k) {
    skeleton::VectorX q = q0;
    for (int j = 6; j < m.nq; ++j) {
      const double lo = m.lower_limit[j], hi = m.upper_limit[j];
      if (std::isfinite(lo) && std::isfinite(hi)) q[j] = q0[j] + (k / 16.0) * 0.5 * (0.5 * (lo + hi) - q0[j]);
    }
    out.push_back(q);
  }
  return out;
}

void BM_EvaluatePosture(benchmark::State& state) {
  ergonomics::Evaluator e(model());
  const std::vector<skeleton::VectorX> qs = postures();
  std::size_t i = 0;
  for (auto _ : state) {
    const ergonomics::Assessment a = e.evaluate(qs[i++ % qs.size()]);
    benchmark::DoNotOptimize(a.rula[0].grand + a.reba[1].score);
  }
}

// what the sim pays per frame: it has the kinematics of the step already
void BM_EvaluateFromKinematics(benchmark::State& state) {
  ergonomics::Evaluator e(model());
  std::vector<skeleton::Data> data;
  for (const skeleton::VectorX& q : postures()) {
    data.emplace_back(model());
    skeleton::forwardKinematics(model(), data.back(), q);
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const ergonomics::Assessment a = e.evaluate(data[i++ % data.size()]);
    benchmark::DoNotOptimize(a.rula[0].grand + a.reba[1].score);
  }
}

void BM_ScoreFromAngles(benchmark::State& state) {
  ergonomics::Evaluator e(model());
  std::vector<ergonomics::PostureAngles> angles;
  for (const skeleton::VectorX& q : postures()) angles.push_back(e.measure(q));
  std::size_t i = 0;
  for (auto _ : state) {
    const ergonomics::PostureAngles& a = angles[i++ % angles.size()];
    int s = 0;
    for (const ergonomics::Side side : {ergonomics::Side::kLeft, ergonomics::Side::kRight})
      s += ergonomics::scoreRula(a, side, {}).grand + ergonomics::scoreReba(a, side, {}).score;
    benchmark::DoNotOptimize(s);
  }
}

}  // namespace

BENCHMARK(BM_EvaluatePosture)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_EvaluateFromKinematics)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ScoreFromAngles)->Unit(benchmark::kMicrosecond);

MANNEQUIN_BENCHMARK_MAIN("bench-ergonomics", "configs/mannequins/male_50th.yaml")
