// bench-balance: multi-contact balance solve time against the number of contacts (2 to 40) and of edges
// per friction cone (4, 6, 8), static (3.69) and variational on the full mannequin (3.107, Alg. 5), each
// against the generic QP→LCP path of the LCP library (lcp::solveQpAsLcp, Annex A) on the same QP in the
// same run. Goals (issue 16): ≤ 250 µs at 20 contacts × 4 edges (variational), ≤ 1 ms at 40 × 8.
#include <cmath>
#include <stdexcept>
#include <vector>

#include "bench_main.hpp"
#include "mannequin/balance/static_balance.hpp"
#include "mannequin/balance/variational_balance.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

using namespace mannequin;
using namespace mannequin::balance;

namespace {

/// Static: N contacts, non-coplanar — 3/4 of them on the floor under two feet, the rest on a wall in
/// front (normal −x) and a table at the side (normal +z at 0.9 m); the CoM desired past the toes.
StaticBalanceProblem staticProblem(int contacts, int edges) {
  StaticBalanceProblem p;
  p.mass = 78.5;
  p.edges = edges;
  p.alpha = 1.0;
  const int floor = std::max(2, (3 * contacts) / 4);
  for (int i = 0; i < floor; ++i) {
    const double x = -0.05 + 0.25 * ((i / 2) % 4) / 3.0, y = (i % 2 ? 0.1 : -0.1) + 0.01 * (i / 8);
    p.contacts.push_back({{x, y, 0}, {0, 0, 1}, 0.6, {0, 0, 0}});
  }
  for (int i = floor; i < contacts; ++i) {
    if (i % 2)
      p.contacts.push_back({{0.6, -0.3 + 0.02 * i, 1.2 + 0.01 * i}, {-1, 0, 0}, 0.5, {0, 0, 0}});
    else
      p.contacts.push_back({{0.3 + 0.01 * i, 0.5, 0.9}, {0, 0, 1}, 0.5, {0, 0, 0}});
  }
  p.desired_com = {0.3, 0, 0.95};
  return p;
}

const skeleton::Model& model() {
  static const skeleton::Model m =
      skeleton::buildMannequin(skeleton::loadMannequinSpec(bench::dataFile("configs/mannequins/male_50th.yaml")));
  return m;
}

/// Sole contact points: n points on the two soles (alternating feet), spread from heel to toe.
std::vector<BodyContact> soles(const skeleton::Model& m, int n) {
  std::vector<BodyContact> out;
  const int per = (n + 1) / 2;
  for (int i = 0; i < n; ++i) {
    const skeleton::Frame& f = m.frames[static_cast<std::size_t>(m.frameIndex(i % 2 ? "sole_l" : "sole_r"))];
    const int k = i / 2;
    const double x = -0.10 + 0.21 * (per > 1 ? static_cast<double>(k) / (per - 1) : 0.5), y = (k % 2 ? 0.04 : -0.04);
    out.push_back({f.joint, f.placement.act(math::Vector3(x, y, 0)), {0, 0, 1}, 0.6, {0, 0, 0}});
  }
  return out;
}

/// Fig. 3.18's configuration: from standing, the left hand taken to a wall 40 cm in front (Alg. 5 with
/// a task, 8 sole points held), computed once.
const skeleton::VectorX& leaningConfiguration() {
  static const skeleton::VectorX q = [] {
    const skeleton::Model& m = model();
    skeleton::VectorX q = skeleton::standingConfiguration(m);
    skeleton::Data d(m);
    skeleton::forwardKinematics(m, d, q);
    VariationalBalanceProblem p;
    p.contacts = soles(m, 8);
    p.held = holdCurrentPoses(p.contacts, d.oMi);
    const math::Vector3 hand = d.oMf[static_cast<std::size_t>(m.frameIndex("hand_l"))].p;
    p.tasks = {{m.frameIndex("hand_l"), math::Vector3(hand.x() + 0.40, hand.y() + 0.05, 1.25)}};
    VariationalBalanceSolver s(m);
    for (int k = 0; k < 150; ++k) {
      const VariationalBalanceResult& r = s.solve(p, q);
      if (r.status != BalanceStatus::kSolved) throw std::runtime_error("leaning configuration: " + r.message);
      q = skeleton::integrate(m, q, r.dq);
    }
    return q;
  }();
  return q;
}

/// Variational: the 50th-percentile male of Fig. 3.18 with its left hand on the wall (one point, normal
/// −x) and N − 1 points on its soles; the right hand reaching forwards (a task); a margin against
/// ±150 N fore-aft pushes at the CoM.
struct Variational {
  skeleton::VectorX q;
  VariationalBalanceProblem p;
};
Variational variationalProblem(int contacts, int edges) {
  const skeleton::Model& m = model();
  Variational v;
  v.q = leaningConfiguration();
  skeleton::Data d(m);
  skeleton::forwardKinematics(m, d, v.q);
  v.p.edges = edges;
  v.p.contacts = soles(m, contacts - 1);
  const skeleton::Frame& hl = m.frames[static_cast<std::size_t>(m.frameIndex("hand_l"))];
  v.p.contacts.push_back({hl.joint, hl.placement.p, {-1, 0, 0}, 0.6, {0, 0, 0}});
  v.p.held = holdCurrentPoses(v.p.contacts, d.oMi);
  v.p.tasks = {{m.frameIndex("hand_r"), d.oMf[static_cast<std::size_t>(m.frameIndex("hand_r"))].p + math::Vector3(0.25, -0.05, 0.15)}};
  skeleton::centerOfMass(m, d);
  for (double s : {1.0, -1.0}) {
    const math::Vector3 F(s * 150, 0, 0);
    math::Vector6 D;
    D << d.com.cross(F), F;
    v.p.force_margins.push_back(D);
  }
  return v;
}

/// The body every case shares: solve once (the case is skipped with the solver's message if that fails),
/// then time either the structured solver (`solve`) or the generic QP→LCP path (lcp::solveQpAsLcp,
/// Annex A) on the QP the solver built. Counters: contacts, edges, the LCP's size and Lemke's pivots.
template <class Solver, class Solve>
void timeSolve(benchmark::State& state, const Solver& s, Solve&& solve, bool generic) {
  state.counters["contacts"] = static_cast<double>(state.range(0));
  state.counters["edges"] = static_cast<double>(state.range(1));
  if (solve().status != BalanceStatus::kSolved) {
    state.SkipWithError(s.result().message.c_str());
    return;
  }
  if (!generic) {
    for (auto _ : state) benchmark::DoNotOptimize(solve());
    state.counters["lcp_size"] = s.result().lcp_size;
    state.counters["pivots"] = s.result().pivots;
    return;
  }
  const lcp::QpProblem g = s.qp().asGenericQp();
  lcp::QpResult r;
  for (auto _ : state) {
    r = lcp::solveQpAsLcp(g);
    benchmark::DoNotOptimize(r.X.data());
  }
  if (r.status != lcp::QpStatus::Solved) state.SkipWithError(r.message);
  state.counters["lcp_size"] = static_cast<double>(r.mu.size());
  state.counters["pivots"] = r.lcp.pivots;
}

void staticCase(benchmark::State& state, bool generic) {
  const StaticBalanceProblem p = staticProblem(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  StaticBalanceSolver s;
  timeSolve(state, s, [&]() -> const StaticBalanceResult& { return s.solve(p); }, generic);
}

void variationalCase(benchmark::State& state, bool generic) {
  const Variational v = variationalProblem(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  VariationalBalanceSolver s(model());
  timeSolve(state, s, [&]() -> const VariationalBalanceResult& { return s.solve(v.p, v.q); }, generic);
}

void BM_StaticBalance(benchmark::State& state) { staticCase(state, false); }
void BM_StaticBalanceGenericQp(benchmark::State& state) { staticCase(state, true); }
void BM_VariationalBalance(benchmark::State& state) { variationalCase(state, false); }
void BM_VariationalBalanceGenericQp(benchmark::State& state) { variationalCase(state, true); }

/// Contacts from `first` to 40 (denser where the curves bend) × 4, 6, 8 edges per cone.
void grid(benchmark::internal::Benchmark* b, int first) {
  b->ArgNames({"contacts", "edges"});
  for (int e : {4, 6, 8})
    for (int c : {2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 30, 35, 40})
      if (c >= first) b->Args({c, e});
  b->Unit(benchmark::kMicrosecond);
}

}  // namespace

BENCHMARK(BM_StaticBalance)->Apply([](benchmark::internal::Benchmark* b) { grid(b, 2); });
BENCHMARK(BM_StaticBalanceGenericQp)->Apply([](benchmark::internal::Benchmark* b) { grid(b, 2); });
// the whole mannequin from 4 contacts (3 sole points and the hand): with 1 or 2 sole points the leaning
// pose under the ±150 N margins has no feasible step (the solver says so), nothing to time
BENCHMARK(BM_VariationalBalance)->Apply([](benchmark::internal::Benchmark* b) { grid(b, 4); });
BENCHMARK(BM_VariationalBalanceGenericQp)->Apply([](benchmark::internal::Benchmark* b) { grid(b, 4); });

MANNEQUIN_BENCHMARK_MAIN("bench-balance", "configs/mannequins/male_50th.yaml")
