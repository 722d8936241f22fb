// bench-kinematics: forward kinematics, Jacobians and CoM Jacobian of the 50th-percentile mannequin
// (43 DoF: 6 root + 37 internal). Goal (issue 2): full kinematics under 10 µs per configuration.
#include <benchmark/benchmark.h>

#include <random>

#include "bench_main.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin::skeleton;

namespace {
struct Fixture {
  Model model;
  Data data;
  std::vector<VectorX> qs;
  std::vector<Matrix6X> segment_J;  // preallocated per-segment frame Jacobians
  Fixture() : model(buildMannequin(MannequinSpec{})), data(model) {
    std::mt19937 g(1);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    for (int i = 0; i < 64; ++i) {
      VectorX q(model.nq);
      for (int k = 0; k < model.nq; ++k) q(k) = u(g);
      qs.push_back(q);
    }
    segment_J.assign(model.segments.size(), Matrix6X::Zero(6, model.nv));
  }
};
Fixture& fixture() {
  static Fixture f;
  return f;
}
}  // namespace

// FK only (all joints and frames)
static void BM_ForwardKinematics(benchmark::State& state) {
  auto& f = fixture();
  size_t i = 0;
  for (auto _ : state) {
    forwardKinematics(f.model, f.data, f.qs[i++ & 63]);
    benchmark::DoNotOptimize(f.data.oMi.back());
  }
}
BENCHMARK(BM_ForwardKinematics);

// FK + all joint Jacobian columns (world) + CoM + CoM Jacobian
static void BM_FullKinematics(benchmark::State& state) {
  auto& f = fixture();
  size_t i = 0;
  for (auto _ : state) {
    computeJointJacobians(f.model, f.data, f.qs[i++ & 63]);
    jacobianCenterOfMass(f.model, f.data);
    benchmark::DoNotOptimize(f.data.Jcom.data());
  }
  state.counters["nv"] = f.model.nv;
}
BENCHMARK(BM_FullKinematics);

// the same, plus one 6×nv local (body) Jacobian extracted per segment (the issue's
// "FK + all segment Jacobians + CoM Jacobian")
static void BM_FullKinematicsWithSegmentJacobians(benchmark::State& state) {
  auto& f = fixture();
  size_t i = 0;
  for (auto _ : state) {
    computeJointJacobians(f.model, f.data, f.qs[i++ & 63]);
    jacobianCenterOfMass(f.model, f.data);
    for (size_t s = 0; s < f.model.segments.size(); ++s)
      jointJacobian(f.model, f.data, f.model.segments[s].joint, ReferenceFrame::kLocal, f.segment_J[s]);
    benchmark::DoNotOptimize(f.segment_J.back().data());
  }
  state.counters["segments"] = static_cast<double>(f.model.segments.size());
}
BENCHMARK(BM_FullKinematicsWithSegmentJacobians);

MANNEQUIN_BENCHMARK_MAIN("bench-kinematics")
