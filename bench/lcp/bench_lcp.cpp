// bench-lcp: Lemke, PGS and the structured path on contact-like (M = J b⁻¹ Jᵀ, 42 columns)
// and well-conditioned SPD LCPs, against Siconos numerics' Lemke and PGS when available.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include "bench_main.hpp"
#include "mannequin/lcp/lemke.hpp"
#include "mannequin/lcp/pgs.hpp"
#include "mannequin/lcp/structured.hpp"
#include "mannequin/lcp/testing.hpp"

#ifdef MANNEQUIN_HAVE_SICONOS
#include <LCP_Solvers.h>
#include <LinearComplementarityProblem.h>
#include <NonSmoothDrivers.h>
#include <NumericsMatrix.h>
#include <SolverOptions.h>
#include <lcp_cst.h>
#endif

using namespace mannequin::lcp;

namespace {

constexpr double kPgsTolerance = 1e-6;
constexpr int kPgsSweeps = 2000;

struct Case {
  LcpProblem lcp;
  Eigen::MatrixXd A;  // M = A Aᵀ
};

Case makeCase(bool contact, Index n) {
  Case c;
  if (contact) {
    auto g = gen::makeContactLike(n, 1);
    c.lcp = g.lcp;
    c.A = g.A;
  } else {
    c.lcp = gen::makeSpd(n, 1);
    factorPsd(c.lcp.M, c.A);
  }
  return c;
}

void record(benchmark::State& st, const LcpResult& r) {
  st.counters["pivots"] = r.pivots;
  st.counters["rel_compl"] = r.residuals.relative_complementarity;
  st.counters["solved"] = r.status == LcpStatus::Solved ? 1 : 0;
}

void ourLemke(benchmark::State& st, bool contact) {
  const Case c = makeCase(contact, st.range(0));
  LemkeWorkspace ws(st.range(0));
  LcpResult r;
  for (auto _ : st) benchmark::DoNotOptimize(r = solveLemke(c.lcp, ws));
  record(st, r);
}

void ourPgs(benchmark::State& st, bool contact) {
  const Case c = makeCase(contact, st.range(0));
  PgsWorkspace ws(st.range(0));
  PgsOptions o;
  o.tolerance = kPgsTolerance;
  o.check_tolerance = kPgsTolerance;
  o.max_iterations = kPgsSweeps;
  LcpResult r;
  for (auto _ : st) benchmark::DoNotOptimize(r = solvePgs(c.lcp, ws, o));
  record(st, r);
}

void ourStructured(benchmark::State& st, bool contact) {
  const Case c = makeCase(contact, st.range(0));
  const StructuredProblem sp{c.A, c.lcp.q};
  StructuredWorkspace ws;
  StructuredOptions o;
  o.warm_start = false;  // cold start every time: no help from the previous identical solve
  LcpResult r;
  for (auto _ : st) benchmark::DoNotOptimize(r = solveStructured(sp, ws, o));
  // residuals against the original M
  r.w = c.lcp.M * r.z + c.lcp.q;
  r.residuals = computeResiduals(c.lcp.q, r.z, r.w);
  record(st, r);
}

// consecutive time steps: q alternates between two nearby vectors (distances grown by up
// to 1 mm, so both stay feasible) and each solve is warm-started from the previous active set
void ourStructuredWarm(benchmark::State& st, bool contact) {
  const Case c = makeCase(contact, st.range(0));
  std::mt19937 rng(7);
  const Eigen::VectorXd q2 = c.lcp.q + gen::uniform(c.lcp.q.size(), 1, 0.0, 1e-3, rng);
  StructuredWorkspace ws;
  LcpResult r;
  bool flip = false;
  for (auto _ : st) {
    flip = !flip;
    benchmark::DoNotOptimize(r = solveStructured(StructuredProblem{c.A, flip ? q2 : c.lcp.q}, ws));
  }
  const Eigen::VectorXd& q = flip ? q2 : c.lcp.q;
  r.w = c.lcp.M * r.z + q;
  r.residuals = computeResiduals(q, r.z, r.w);
  record(st, r);
}

#ifdef MANNEQUIN_HAVE_SICONOS
void siconos(benchmark::State& st, bool contact, int solver) {
  const Index n = st.range(0);
  const Case c = makeCase(contact, n);
  // Siconos owns a malloc'd column-major copy of M
  double* data = static_cast<double*>(std::malloc(sizeof(double) * static_cast<std::size_t>(n * n)));
  std::memcpy(data, c.lcp.M.data(), sizeof(double) * static_cast<std::size_t>(n * n));
  NumericsMatrix* M = NM_create_from_data(NM_DENSE, static_cast<int>(n), static_cast<int>(n), data);
  Eigen::VectorXd q = c.lcp.q, z(n), w(n);
  LinearComplementarityProblem problem{static_cast<int>(n), M, q.data()};
  SolverOptions* opt = solver_options_create(solver);
  if (solver == SICONOS_LCP_PGS) {
    opt->iparam[SICONOS_IPARAM_MAX_ITER] = kPgsSweeps;
    opt->dparam[SICONOS_DPARAM_TOL] = kPgsTolerance;
  } else {
    opt->iparam[SICONOS_IPARAM_MAX_ITER] = 1000000;
  }
  int info = 0;
  for (auto _ : st) {
    z.setZero();
    w.setZero();
    info = linearComplementarity_driver(&problem, z.data(), w.data(), opt);
    benchmark::DoNotOptimize(z.data());
  }
  LcpResult r;
  r.z = z.cwiseMax(0.0);
  r.w = c.lcp.M * r.z + c.lcp.q;
  r.residuals = computeResiduals(c.lcp.q, r.z, r.w);
  r.pivots = opt->iparam[SICONOS_IPARAM_ITER_DONE];
  r.status = info == 0 ? LcpStatus::Solved : LcpStatus::PivotLimit;
  record(st, r);
  solver_options_delete(opt);
  NM_free(M);
}
#endif

void registerAll() {
  const int sizes[] = {10, 50, 100, 280, 500, 1000};
  for (bool contact : {true, false}) {
    const std::string kind = contact ? "contact" : "spd";
    for (int n : sizes) {
      auto unit = n >= 280 ? benchmark::kMillisecond : benchmark::kMicrosecond;
      benchmark::RegisterBenchmark(("lemke/" + kind).c_str(), ourLemke, contact)->Arg(n)->Unit(unit)->MinTime(0.2);
      benchmark::RegisterBenchmark(("pgs/" + kind).c_str(), ourPgs, contact)->Arg(n)->Unit(unit)->MinTime(0.2);
      benchmark::RegisterBenchmark(("structured/" + kind).c_str(), ourStructured, contact)->Arg(n)->Unit(unit)->MinTime(0.2);
      if (contact) {
        benchmark::RegisterBenchmark("structured_warm/contact", ourStructuredWarm, contact)->Arg(n)->Unit(unit)->MinTime(0.2);
      }
#ifdef MANNEQUIN_HAVE_SICONOS
      // Siconos' dense Lemke grows like n³ per solve: capped at n = 500 (≈ seconds per run)
      if (n <= 500) {
        benchmark::RegisterBenchmark(("siconos_lemke/" + kind).c_str(), siconos, contact, int(SICONOS_LCP_LEMKE))->Arg(n)->Unit(unit)->MinTime(0.2);
      }
      benchmark::RegisterBenchmark(("siconos_pgs/" + kind).c_str(), siconos, contact, int(SICONOS_LCP_PGS))->Arg(n)->Unit(unit)->MinTime(0.2);
#endif
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
#ifndef MANNEQUIN_HAVE_SICONOS
  std::fprintf(stderr, "bench-lcp: Siconos numerics not found at build time, comparison skipped\n");
#endif
  return mannequin::bench::guarded("bench-lcp", [&] {
    registerAll();
    return mannequin::bench::runSpecified(argc, argv);
  });
}
