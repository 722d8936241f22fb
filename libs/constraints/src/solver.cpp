#include "mannequin/constraints/solver.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace mannequin::constraints {

const char* solverUsedName(SolverUsed s) {
  switch (s) {
    case SolverUsed::kNone: return "none";
    case SolverUsed::kLemke: return "lemke";
    case SolverUsed::kStructured: return "structured";
    case SolverUsed::kPgs: return "pgs";
    case SolverUsed::kFailed: return "failed";
  }
  return "failed";
}

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kPanel = 64;  // column panels of the Delassus assembly

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::vector<int> systemSizes(const std::vector<ConstrainedSystem*>& systems, const SolverOptions& o) {
  if (systems.empty()) throw std::invalid_argument("ConstraintSolver: no system");
  if (systems.size() > 64) throw std::invalid_argument("ConstraintSolver: more than 64 systems");
  if (o.max_rows < 1 || o.max_friction_rows < 0 || o.max_friction_rows > o.max_rows || o.max_edges < 1 ||
      o.refine_rounds < 0)
    throw std::invalid_argument(
        "ConstraintSolver: options need max_rows >= 1, 0 <= max_friction_rows <= max_rows, max_edges >= 1, "
        "refine_rounds >= 0");
  std::vector<int> nv;
  for (std::size_t s = 0; s < systems.size(); ++s) {
    if (systems[s] == nullptr) throw std::invalid_argument("ConstraintSolver: system " + std::to_string(s) + " is null");
    nv.push_back(systems[s]->nv());
  }
  return nv;
}

}  // namespace

// The step's LCP matrix, never formed: M = [Σ_s X_sᵀ X_s  0; 0 0] (force rows; X_s = L_s⁻ᵀ R_sᵀ) plus
// the friction structure (w_edge = … + γ, w_γ = μλ − Σβ): Lemke's product form reads only the
// columns of the variables entering its basis, O(n Σ nv_s) each, instead of the O(n² Σ nv_s) product.
class DelassusOperator final : public lcp::LcpMatrixOperator {
 public:
  struct Data {
    const std::vector<Eigen::MatrixXd>* X = nullptr;  // per system: nv_s × cap_f (leading nF columns valid)
    std::vector<Eigen::VectorXd>* scratch = nullptr;  // per system: nv_s
    std::uint64_t touched = 0;
    int ns = 0, nF = 0, n = 0;
    const std::vector<int>* fric = nullptr;  // friction rows: (p, first edge, edges, γ) quadruples
    int nfric = 0;
    const std::vector<double>* mu = nullptr;  // per friction row
    double max_abs = 0.0;
    std::vector<Eigen::MatrixXd>* gathered = nullptr;  // per system: nv_s × cap_f (principal())
    std::vector<int>* where = nullptr;                 // cap_n entries, all −1 between calls
  };
  explicit DelassusOperator(const Data& d) : d_(d) {}
  Eigen::Index size() const override { return d_.n; }
  void column(Eigen::Index j, Eigen::Ref<Eigen::VectorXd> out) const override {
    out.setZero();
    if (j < d_.nF) {
      for (int s = 0; s < d_.ns; ++s) {
        if (!((d_.touched >> s) & 1u)) continue;
        const auto X = (*d_.X)[static_cast<std::size_t>(s)].leftCols(d_.nF);
        out.head(d_.nF).noalias() += X.transpose() * X.col(j);
      }
    }
    for (int f = 0; f < d_.nfric; ++f) {
      const int* e = &(*d_.fric)[static_cast<std::size_t>(4 * f)];
      if (j == e[0]) out[e[3]] += (*d_.mu)[static_cast<std::size_t>(f)];
      if (j >= e[1] && j < e[1] + e[2]) out[e[3]] -= 1.0;
      if (j == e[3]) out.segment(e[1], e[2]).array() += 1.0;
    }
  }
  void multiply(const lcp::VectorView& z, Eigen::Ref<Eigen::VectorXd> out) const override {
    out.setZero();
    for (int s = 0; s < d_.ns; ++s) {
      if (!((d_.touched >> s) & 1u)) continue;
      const auto X = (*d_.X)[static_cast<std::size_t>(s)].leftCols(d_.nF);
      Eigen::VectorXd& t = (*d_.scratch)[static_cast<std::size_t>(s)];
      t.noalias() = X * z.head(d_.nF);
      out.head(d_.nF).noalias() += X.transpose() * t;
    }
    for (int f = 0; f < d_.nfric; ++f) {
      const int* e = &(*d_.fric)[static_cast<std::size_t>(4 * f)];
      out[e[3]] += (*d_.mu)[static_cast<std::size_t>(f)] * z[e[0]] - z.segment(e[1], e[2]).sum();
      out.segment(e[1], e[2]).array() += z[e[3]];
    }
  }
  double maxAbs() const override { return d_.max_abs; }
  // the principal block on idx (ascending): Σ_s X_s,Bᵀ X_s,B over the force rows of idx (one product
  // of gathered columns instead of k column reads) plus the friction structure's entries
  void principal(const int* idx, Eigen::Index k, Eigen::Ref<Eigen::MatrixXd> out,
                 Eigen::Ref<Eigen::VectorXd> /*scratch*/) const override {
    out.setZero();
    Eigen::Index kF = 0;
    while (kF < k && idx[kF] < d_.nF) ++kF;
    if (kF > 0) {
      for (int s = 0; s < d_.ns; ++s) {
        if (!((d_.touched >> s) & 1u)) continue;
        const auto us = static_cast<std::size_t>(s);
        const Eigen::MatrixXd& X = (*d_.X)[us];
        auto G = (*d_.gathered)[us].leftCols(kF);
        for (Eigen::Index c = 0; c < kF; ++c) G.col(c) = X.col(idx[c]);
        out.topLeftCorner(kF, kF).noalias() += G.transpose() * G;
      }
    }
    std::vector<int>& at = *d_.where;
    for (Eigen::Index c = 0; c < k; ++c) at[static_cast<std::size_t>(idx[c])] = static_cast<int>(c);
    for (int f = 0; f < d_.nfric; ++f) {
      const int* e = &(*d_.fric)[static_cast<std::size_t>(4 * f)];
      const int g = at[static_cast<std::size_t>(e[3])];
      if (g < 0) continue;
      const int p = at[static_cast<std::size_t>(e[0])];
      if (p >= 0) out(g, p) += (*d_.mu)[static_cast<std::size_t>(f)];
      for (int j = e[1]; j < e[1] + e[2]; ++j) {
        const int b = at[static_cast<std::size_t>(j)];
        if (b < 0) continue;
        out(g, b) -= 1.0;
        out(b, g) += 1.0;
      }
    }
    for (Eigen::Index c = 0; c < k; ++c) at[static_cast<std::size_t>(idx[c])] = -1;
  }

 private:
  Data d_;
};

// LCP layout of a step: z = [normal/limit rows and bilateral halves (nN) | friction edges (nE) |
// sliding speeds γ (nG)]; the force rows are the first nF = nN + nE. Buffers whose size is linear in
// the capacity are allocated here; the n²-sized ones (M for PGS, Lemke's tableau, PGS's Mᵀ) grow to the
// largest LCP seen (never beyond the capacity), so solve() allocates nothing after that warm-up.
struct ConstraintSolver::Impl {
  using Index = Eigen::Index;
  int cap_n = 0, cap_f = 0, cap_nn = 0;  // LCP, force rows, frictionless rows
  int m_total = 0;                       // Σ nv_s
  std::vector<Eigen::MatrixXd> Rt;       // per system: nv_s × cap_f, force rows R_s (transposed)
  std::vector<Eigen::MatrixXd> X;        // per system: nv_s × cap_f, L_s⁻ᵀ R_sᵀ
  std::vector<Eigen::VectorXd> gamma;    // per system: nv_s, Γ_s
  std::vector<Eigen::VectorXd> velocity; // per system: nv_s, q̇_s of the current answer (refinement)
  std::vector<int> pos, neg, edge, gam;  // per row: index of λ (+ half), − half, first edge, γ
  std::vector<int> fric;                 // per friction row: p, first edge, edges, γ (DelassusOperator)
  std::vector<double> mu;                // per friction row
  Eigen::VectorXd diag;                  // cap_f: diagonal of Σ_s X_sᵀ X_s
  Eigen::MatrixXd M;                     // grows: n × n (PGS's frictionless block, on a fallback)
  Eigen::VectorXd q;                     // cap_n
  Eigen::VectorXd q_base;                // cap_n: q without the distance terms (refinement)
  Eigen::VectorXd z_prev;                // cap_n: the answer before a re-solve (refinement)
  Eigen::MatrixXd A;                     // cap_nn × Σ nv_s: frictionless A = [R_s L_s⁻¹]_s
  lcp::LcpResult result;                 // cap_n
  // warm start: the basis guessed from the previous step's answer (rows matched by RowKey)
  struct RowKey {
    int producer = -1, tag = -1, system_a = -1, system_b = -1, edges = 0;
    RowSource source = RowSource::kOther;
    RowKind kind = RowKind::kUnilateral;
    bool operator==(const RowKey&) const = default;
  };
  std::vector<Eigen::MatrixXd> gathered;     // per system: nv_s × cap_f (DelassusOperator::principal)
  std::vector<int> where;                    // cap_n, −1 (DelassusOperator::principal)
  std::vector<std::uint8_t> basic;           // cap_n: the guess for this solve
  std::vector<RowKey> prev_key;              // per row of the previous step
  std::vector<int> prev_pos, prev_neg, prev_edge, prev_gam;  // its LCP layout
  std::vector<std::uint8_t> prev_basic;      // cap_n: basic in its answer (degenerate zeros included)
  std::vector<double> prev_z;                // cap_n: its answer
  std::vector<std::uint8_t> basic2;          // cap_n: the second guess (degenerate edges mirrored)
  int prev_nr = 0;
  lcp::LemkeWorkspace lemke;
  lcp::StructuredWorkspace structured;
  lcp::PgsWorkspace pgs;
  Index grown = 0;                       // n² buffers hold this size
  // cos and sin of the edge angles 2πk/m: edge_cs[m][2k], edge_cs[m][2k + 1] (m = 1..max_edges)
  std::vector<std::vector<double>> edge_cs;

  void grow(Index n) {
    if (n <= grown) return;
    const Index g = std::min<Index>(cap_n, std::max<Index>(n, 2 * grown));
    M.resize(g, g);
    lemke.reserve(g);
    pgs.reserve(std::min<Index>(g, cap_nn));
    grown = g;
  }
};

namespace {
// the frictionless Delassus block Σ_s X_sᵀ X_s (nN × nN, in im.M) for PGS: only on a fallback
template <typename Impl>
void pgsMatrix(Impl& im, std::uint64_t touched, int ns, int nN) {
  auto M = im.M.topLeftCorner(nN, nN);
  M.setZero();
  for (int s = 0; s < ns; ++s) {
    if (!((touched >> s) & 1u)) continue;
    const auto X = im.X[static_cast<std::size_t>(s)].leftCols(nN);
    for (int i0 = 0; i0 < nN; i0 += kPanel) {
      const int ni = std::min(kPanel, nN - i0);
      for (int j0 = i0; j0 < nN; j0 += kPanel) {
        const int nj = std::min(kPanel, nN - j0);
        M.block(i0, j0, ni, nj).noalias() += X.middleCols(i0, ni).transpose() * X.middleCols(j0, nj);
        if (j0 != i0) M.block(j0, i0, nj, ni) = M.block(i0, j0, ni, nj).transpose();
      }
    }
  }
}
}  // namespace

ConstraintSolver::ConstraintSolver(std::vector<ConstrainedSystem*> systems, const SolverOptions& options)
    : impl_(std::make_unique<Impl>()),
      systems_(std::move(systems)),
      options_(options),
      rows_(systemSizes(systems_, options), options.max_rows, options.max_friction_rows, options.max_edges) {
  Impl& im = *impl_;
  im.cap_nn = 2 * options.max_rows;  // a bilateral row is two LCP rows
  im.cap_f = im.cap_nn + options.max_friction_rows * options.max_edges;
  im.cap_n = im.cap_f + options.max_friction_rows;
  for (ConstrainedSystem* s : systems_) {
    const int nv = s->nv();
    im.Rt.emplace_back(Eigen::MatrixXd::Zero(nv, im.cap_f));
    im.X.emplace_back(Eigen::MatrixXd::Zero(nv, im.cap_f));
    im.gamma.emplace_back(Eigen::VectorXd::Zero(nv));
    im.velocity.emplace_back(Eigen::VectorXd::Zero(nv));
    im.gathered.emplace_back(Eigen::MatrixXd::Zero(nv, im.cap_f));
    im.m_total += nv;
  }
  const auto mr = static_cast<std::size_t>(options.max_rows);
  im.pos.assign(mr, -1);
  im.neg.assign(mr, -1);
  im.edge.assign(mr, -1);
  im.gam.assign(mr, -1);
  im.fric.assign(4 * mr, 0);
  im.mu.assign(mr, 0.0);
  im.where.assign(static_cast<std::size_t>(im.cap_n), -1);
  im.basic.assign(static_cast<std::size_t>(im.cap_n), 0);
  im.prev_basic.assign(static_cast<std::size_t>(im.cap_n), 0);
  im.prev_z.assign(static_cast<std::size_t>(im.cap_n), 0.0);
  im.basic2.assign(static_cast<std::size_t>(im.cap_n), 0);
  im.prev_key.assign(mr, Impl::RowKey{});
  im.prev_pos.assign(mr, -1);
  im.prev_neg.assign(mr, -1);
  im.prev_edge.assign(mr, -1);
  im.prev_gam.assign(mr, -1);
  im.diag = Eigen::VectorXd::Zero(im.cap_f);
  im.edge_cs.resize(static_cast<std::size_t>(options.max_edges) + 1);
  for (int m = 1; m <= options.max_edges; ++m) {
    for (int k = 0; k < m; ++k) {
      const double th = 2.0 * std::numbers::pi * k / m;
      im.edge_cs[static_cast<std::size_t>(m)].push_back(std::cos(th));
      im.edge_cs[static_cast<std::size_t>(m)].push_back(std::sin(th));
    }
  }
  im.q = Eigen::VectorXd::Zero(im.cap_n);
  im.q_base = Eigen::VectorXd::Zero(im.cap_n);
  im.z_prev = Eigen::VectorXd::Zero(im.cap_n);
  im.A = Eigen::MatrixXd::Zero(im.cap_nn, im.m_total);
  im.result.reserve(im.cap_n);
  im.structured.reserve(im.cap_nn, im.m_total);
  producers_.reserve(16);
}

ConstraintSolver::~ConstraintSolver() = default;

int ConstraintSolver::addProducer(RowProducer* producer) {
  if (producer == nullptr) throw std::invalid_argument("ConstraintSolver::addProducer: null producer");
  producers_.push_back(producer);
  return static_cast<int>(producers_.size()) - 1;
}

const SolveReport& ConstraintSolver::solve(double dt) {
  Impl& im = *impl_;
  SolveReport& rep = report_;
  rep = SolveReport{};
  const auto t0 = Clock::now();
  if (!(dt > 0.0) || !std::isfinite(dt)) {  // no rows at a meaningless step
    rep.solver = SolverUsed::kFailed;
    rep.fallback = true;
    rep.dropped = rows_.dropped();
    ++failures_;
    ++unsolved_;
    return rep;
  }

  // 1. rows
  rows_.clear();
  for (std::size_t p = 0; p < producers_.size(); ++p) producers_[p]->addRows(static_cast<int>(p), dt, rows_);
  const int ns = rows_.numSystems();
  const auto t1 = Clock::now();
  rep.produce_s = seconds(t0, t1);
  if (rows_.size() == 0) {
    for (std::size_t p = 0; p < producers_.size(); ++p) producers_[p]->solved(static_cast<int>(p), rows_);
    return rep;
  }
  lcp::LcpResult& res = im.result;
  int nr = 0, nN = 0, nF = 0, nz = 0;  // nz: force rows of the answer
  std::uint64_t touched = 0;
  int rounds_left = options_.refine_rounds;
  int n_lcp = 0;  // size of the LCP of the answer
  auto t2 = t1;
  const auto keyOf = [&](int r) {
    const RowInfo& in = rows_.info(r);
    return Impl::RowKey{in.producer, in.tag, in.system_a, in.system_b,
                        rows_.frictionSlot(r) >= 0 ? in.friction_edges : 0, in.source, in.kind};
  };
  // warm start: each row matched to the previous step's row with the same key (producers emit their
  // rows in a stable order, so a cursor with a short look-ahead finds them), its variables flagged as
  // they were in the previous basis; nullptr when nothing matched (a cold start). The second guess
  // (im.basic2, *second; nullptr when it is the same) mirrors each cone's degenerate basic edges
  // (β = 0 in the basis) to the opposite edges (k ↔ k + m/2, m even): with a contact at rest, which
  // of two opposite edges is the degenerate basic one fixes the sign of its sliding speed γ = ∓t_k·v, so
  // a tangential velocity of 1e-5 m/s that changes sign from one step to the next (a hand at the edge
  // of its cone) makes the first guess fail by a γ < 0 and the mirrored one right.
  const auto guessFromPrevious = [&](int n, const std::uint8_t** second) -> const std::uint8_t* {
    *second = nullptr;
    if (!options_.warm_start || im.prev_nr == 0) return nullptr;
    constexpr int kLookAhead = 8;
    std::fill_n(im.basic.begin(), n, std::uint8_t{0});
    std::fill_n(im.basic2.begin(), n, std::uint8_t{0});
    bool any = false, mirrored = false;
    for (int r = 0, c = 0; r < nr; ++r) {
      const Impl::RowKey key = keyOf(r);
      int found = -1;
      for (int t = c; t < std::min(im.prev_nr, c + kLookAhead); ++t) {
        if (im.prev_key[static_cast<std::size_t>(t)] == key) {
          found = t;
          break;
        }
      }
      if (found < 0) continue;
      c = found + 1;
      const auto ur = static_cast<std::size_t>(r), uf = static_cast<std::size_t>(found);
      const auto copy = [&](int to, int from, int count) {
        if (to < 0 || from < 0) return;
        for (int j = 0; j < count; ++j) {
          const std::uint8_t b = im.prev_basic[static_cast<std::size_t>(from + j)];
          im.basic[static_cast<std::size_t>(to + j)] = b;
          any = any || b != 0;
        }
      };
      copy(im.pos[ur], im.prev_pos[uf], 1);
      copy(im.neg[ur], im.prev_neg[uf], 1);
      copy(im.edge[ur], im.prev_edge[uf], key.edges);
      copy(im.gam[ur], im.prev_gam[uf], 1);
      // the second guess's edges of this row
      const int m = key.edges;
      if (im.edge[ur] < 0 || im.prev_edge[uf] < 0) continue;
      for (int k = 0; k < m; ++k) {
        const auto from = static_cast<std::size_t>(im.prev_edge[uf] + k);
        const bool positive = im.prev_basic[from] != 0 && im.prev_z[from] > 0.0;
        bool degenerate_opposite = false;
        if (m % 2 == 0) {
          const auto opp = static_cast<std::size_t>(im.prev_edge[uf] + (k + m / 2) % m);
          degenerate_opposite = im.prev_basic[opp] != 0 && !(im.prev_z[opp] > 0.0);
        }
        const std::uint8_t b2 = positive || degenerate_opposite ? 1 : 0;
        im.basic2[static_cast<std::size_t>(im.edge[ur] + k)] = b2;
        mirrored = mirrored || b2 != im.basic[static_cast<std::size_t>(im.edge[ur] + k)];
      }
    }
    if (!any) return nullptr;
    if (mirrored) {  // the rest as in the first guess
      for (int r = 0; r < nr; ++r) {
        const auto ur = static_cast<std::size_t>(r);
        for (int i : {im.pos[ur], im.neg[ur], im.gam[ur]})
          if (i >= 0) im.basic2[static_cast<std::size_t>(i)] = im.basic[static_cast<std::size_t>(i)];
      }
      *second = im.basic2.data();
    }
    return im.basic.data();
  };
  // steps 2–3 (and 5) — again from the assembly when a refine() added rows
  for (bool assemble = true; assemble;) {
    assemble = false;
    nr = rows_.size();
    rep.rows = nr;
    rep.dropped = rows_.dropped();
    // 2. assembly: indices
    int nE = 0, nG = 0;
    nN = 0;
    touched = 0;
    for (int r = 0; r < nr; ++r) {
      const RowInfo& in = rows_.info(r);
      const auto ur = static_cast<std::size_t>(r);
      im.pos[ur] = nN++;
      im.neg[ur] = in.kind == RowKind::kBilateral ? nN++ : -1;
      for (int s = 0; s < ns; ++s) touched |= rows_.touches(r, s) ? std::uint64_t{1} << s : 0;
    }
    for (int r = 0; r < nr; ++r) {
      const auto ur = static_cast<std::size_t>(r);
      if (rows_.frictionSlot(r) >= 0) {
        im.edge[ur] = nN + nE;
        nE += rows_.info(r).friction_edges;
        ++nG;
      } else {
        im.edge[ur] = -1;
      }
    }
    nF = nN + nE;
    const int n = nF + nG;
    for (int r = 0, g = 0; r < nr; ++r) im.gam[static_cast<std::size_t>(r)] = rows_.frictionSlot(r) >= 0 ? nF + g++ : -1;
    im.grow(n);
    auto q = im.q.head(n);
    q.setZero();
    auto diag = im.diag.head(nF);
    diag.setZero();
    // force rows per touched system, X_s = L_s⁻ᵀ R_sᵀ (the Delassus matrix Σ_s X_sᵀ X_s is not formed:
    // DelassusOperator), q = R q̇_free + d/δt
    for (int s = 0; s < ns; ++s) {
      if (!((touched >> s) & 1u)) continue;
      const auto us = static_cast<std::size_t>(s);
      const RowSet::RowMatrix& J = rows_.jacobians(s);
      auto Rt = im.Rt[us].leftCols(nF);
      for (int r = 0; r < nr; ++r) {
        const auto ur = static_cast<std::size_t>(r);
        Rt.col(im.pos[ur]) = J.row(r).transpose();
        if (im.neg[ur] >= 0) Rt.col(im.neg[ur]) = -J.row(r).transpose();
        const int slot = rows_.frictionSlot(r);
        if (slot < 0) continue;
        const int m = rows_.info(r).friction_edges;
        const double* cs = im.edge_cs[static_cast<std::size_t>(m)].data();
        for (int k = 0; k < m; ++k)
          Rt.col(im.edge[ur] + k) =
              (cs[2 * k] * rows_.tangents(s, 0).row(slot) + cs[2 * k + 1] * rows_.tangents(s, 1).row(slot)).transpose();
      }
      // X = L⁻ᵀ Rᵀ (b = Lᵀ L along the tree of coordinates): a row on a body keeps the support of
      // the coordinates moving that body, so each solve costs its branch's depth², not nv²; a
      // bilateral row's − half is −(its + half), a cone's edges are combinations of L⁻ᵀt1 and L⁻ᵀt2
      auto X = im.X[us].leftCols(nF);
      const math::TreeCholesky& factor = systems_[us]->frictionFactor();
      Eigen::VectorXd& u1 = im.velocity[us];  // free until the refinement
      Eigen::VectorXd& u2 = im.gamma[us];     // free until the solve
      for (int r = 0; r < nr; ++r) {
        const auto ur = static_cast<std::size_t>(r);
        auto xp = X.col(im.pos[ur]);
        xp = Rt.col(im.pos[ur]);
        factor.halfSolveInPlace(xp);
        if (im.neg[ur] >= 0) X.col(im.neg[ur]) = -xp;
        const int slot = rows_.frictionSlot(r);
        if (slot < 0) continue;
        const int m = rows_.info(r).friction_edges;
        const double* cs = im.edge_cs[static_cast<std::size_t>(m)].data();
        u1 = rows_.tangents(s, 0).row(slot).transpose();
        u2 = rows_.tangents(s, 1).row(slot).transpose();
        factor.halfSolveInPlace(u1);
        factor.halfSolveInPlace(u2);
        for (int k = 0; k < m; ++k) X.col(im.edge[ur] + k) = cs[2 * k] * u1 + cs[2 * k + 1] * u2;
      }
      diag += X.colwise().squaredNorm().transpose();
      q.head(nF).noalias() += Rt.transpose() * systems_[us]->qdotFree();
    }
    im.q_base.head(n) = q;
    // the distance terms max(±d/δt, −v_rec) + ±correction/δt of the force rows
    const auto addDistances = [&] {
      for (int r = 0; r < nr; ++r) {
        const RowInfo& in = rows_.info(r);
        const auto ur = static_cast<std::size_t>(r);
        const double v = std::isfinite(in.recovery_speed) ? std::max(0.0, in.recovery_speed) : 0.0;
        const double c = std::isfinite(in.correction) ? in.correction / dt : 0.0;
        q[im.pos[ur]] += std::max(in.distance / dt, -v) + c;
        if (im.neg[ur] >= 0) q[im.neg[ur]] += std::max(-in.distance / dt, -v) - c;
      }
    };
    addDistances();
    double max_abs = nF > 0 ? diag.maxCoeff() : 0.0;  // |M_ij| ≤ √(M_ii M_jj) on the PSD block
    int nfric = 0;
    for (int r = 0; r < nr; ++r) {
      const RowInfo& in = rows_.info(r);
      const auto ur = static_cast<std::size_t>(r);
      if (im.gam[ur] < 0) continue;
      // edges: w = t_k q̇ + γ; cone: w_γ = μλ − Σβ
      const auto f = static_cast<std::size_t>(nfric++);
      im.fric[4 * f] = im.pos[ur];
      im.fric[4 * f + 1] = im.edge[ur];
      im.fric[4 * f + 2] = in.friction_edges;
      im.fric[4 * f + 3] = im.gam[ur];
      im.mu[f] = in.mu;
      max_abs = std::max({max_abs, std::abs(in.mu), 1.0});
    }
    DelassusOperator::Data od;
    od.X = &im.X;
    od.scratch = &im.gamma;  // free until step 4
    od.touched = touched;
    od.ns = ns;
    od.nF = nF;
    od.n = n;
    od.fric = &im.fric;
    od.nfric = nfric;
    od.mu = &im.mu;
    od.max_abs = max_abs;
    od.gathered = &im.gathered;
    od.where = &im.where;
    const DelassusOperator M(od);
    t2 = Clock::now();
    rep.assemble_s = seconds(t1, t2);
    rep.lcp_size = n;

    // 3. Lemke, then the frictionless problem by the structured solver, then PGS
    nz = 0;
    n_lcp = n;
    bool warm = false;
    const std::uint8_t* second = nullptr;
    const std::uint8_t* first = guessFromPrevious(n, &second);
    const lcp::LcpStatus ls = lcp::solveLemkeWarm(M, q, first, second, im.lemke, options_.lemke, res, &warm);
    rep.lcp_solves += 1;
    rep.warm += warm ? 1 : 0;
    rep.lemke_status = ls;
    rep.pivots = res.pivots;
    if (ls == lcp::LcpStatus::Solved && res.z.head(n).allFinite()) {
      rep.solver = SolverUsed::kLemke;
      nz = nF;
      // 5. refinement: the producers correct the first-order prediction of their rows with the
      // velocities of this answer; the LCP is solved again with the same M (only q changes)
      for (; rounds_left > 0; --rounds_left) {
        for (int r = 0; r < nr; ++r) {  // λ of the current answer, for the producers
          const auto ur = static_cast<std::size_t>(r);
          rows_.info(r).lambda = res.z[im.pos[ur]] - (im.neg[ur] >= 0 ? res.z[im.neg[ur]] : 0.0);
        }
        for (int s = 0; s < ns; ++s) {
          const auto us = static_cast<std::size_t>(s);
          Eigen::VectorXd& v = im.velocity[us];
          if ((touched >> s) & 1u) {
            v.noalias() = im.Rt[us].leftCols(nF) * res.z.head(nF);
            systems_[us]->frictionFactor().solveInPlace(v);  // b⁻¹Γ
            v += systems_[us]->qdotFree();
          } else {
            v = systems_[us]->qdotFree();
          }
        }
        bool again = false;
        for (std::size_t p = 0; p < producers_.size(); ++p)
          again = producers_[p]->refine(static_cast<int>(p), dt, rows_, im.velocity) || again;
        if (rows_.size() != nr) {  // late rows: assemble and solve again
          --rounds_left;
          ++rep.refine_rounds;
          assemble = true;
          break;
        }
        if (!again) break;
        im.z_prev.head(n) = res.z.head(n);
        q = im.q_base.head(n);
        addDistances();
        // the current answer's basis is the guess (only q moved, by O(δt²))
        std::copy_n(im.lemke.basis(), n, im.basic.begin());
        const lcp::LcpStatus rs = lcp::solveLemkeWarm(M, q, options_.warm_start ? im.basic.data() : nullptr, im.lemke,
                                                      options_.lemke, res, &warm);
        rep.lcp_solves += 1;
        rep.warm += warm ? 1 : 0;
        ++rep.refine_rounds;
        rep.pivots = res.pivots;
        if (rs != lcp::LcpStatus::Solved || !res.z.head(n).allFinite()) {
          res.z.head(n) = im.z_prev.head(n);  // keep the last good answer
          break;
        }
      }
    } else {
      rep.fallback = true;
      ++failures_;
      rep.lcp_size = nN;
      // frictionless A = [R_s L_s⁻¹]_s
      int col = 0;
      for (int s = 0; s < ns; ++s) {
        if (!((touched >> s) & 1u)) continue;
        const auto Xs = im.X[static_cast<std::size_t>(s)].leftCols(nN);
        im.A.block(0, col, nN, Xs.rows()) = Xs.transpose();
        col += static_cast<int>(Xs.rows());
      }
      const auto An = im.A.topLeftCorner(nN, col);
      const auto qn = im.q.head(nN);
      const auto solvedWith = [&](lcp::LcpStatus st) { return st == lcp::LcpStatus::Solved && res.z.head(nN).allFinite(); };
      if (solvedWith(lcp::solveStructured(An, qn, im.structured, options_.structured, res))) {
        rep.solver = SolverUsed::kStructured;
        nz = nN;
      } else {
        pgsMatrix(im, touched, ns, nN);
        if (solvedWith(lcp::solvePgs(im.M.topLeftCorner(nN, nN), qn, im.pgs, options_.pgs, res))) {
          rep.solver = SolverUsed::kPgs;
          nz = nN;
        } else {
          rep.solver = SolverUsed::kFailed;
          ++unsolved_;
        }
      }
      rep.pivots = res.pivots;
    }
  }  // assembly passes
  const auto z = res.z.head(std::max(nz, 0));

  // 4. forces back to the systems and the rows
  if (nz > 0) {
    for (int s = 0; s < ns; ++s) {
      if (!((touched >> s) & 1u)) continue;
      const auto us = static_cast<std::size_t>(s);
      im.gamma[us].noalias() = im.Rt[us].leftCols(nz) * z;
      if (!systems_[us]->applyConstraintForce(im.gamma[us])) ++rep.refused_forces;  // that system keeps its free motion
    }
  }
  for (int r = 0; r < nr; ++r) {
    RowInfo& in = rows_.info(r);
    const auto ur = static_cast<std::size_t>(r);
    if (nz == 0) {
      in.lambda = in.friction = 0.0;
      continue;
    }
    const double plus = z[im.pos[ur]], minus = im.neg[ur] >= 0 ? z[im.neg[ur]] : 0.0;
    in.lambda = plus - minus;
    rep.active += (plus > 0.0 || minus > 0.0) ? 1 : 0;
    in.friction = 0.0;
    if (im.edge[ur] >= 0 && nz == nF) {
      const int m = in.friction_edges;
      double fx = 0.0, fy = 0.0;
      const double* cs = im.edge_cs[static_cast<std::size_t>(m)].data();
      for (int k = 0; k < m; ++k) {
        fx += z[im.edge[ur] + k] * cs[2 * k];
        fy += z[im.edge[ur] + k] * cs[2 * k + 1];
      }
      in.friction = std::hypot(fx, fy);
    }
  }
  // this answer's basis, the next step's guess
  const int n_kept = rep.solver == SolverUsed::kLemke ? n_lcp : 0;  // a fallback's answer: no guess
  im.prev_nr = nr;
  for (int r = 0; r < nr; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    im.prev_key[ur] = keyOf(r);
    im.prev_pos[ur] = im.pos[ur];
    im.prev_neg[ur] = im.neg[ur];
    im.prev_edge[ur] = im.edge[ur];
    im.prev_gam[ur] = im.gam[ur];
  }
  // Lemke's final basis (degenerate zeros included: without them the guessed block may be singular)
  const std::uint8_t* const basis = im.lemke.basis();
  for (int i = 0; i < n_lcp; ++i) {
    im.prev_basic[static_cast<std::size_t>(i)] = i < n_kept && basis[i] != 0 ? 1 : 0;
    im.prev_z[static_cast<std::size_t>(i)] = i < n_kept ? res.z[i] : 0.0;
  }
  rep.solve_s = seconds(t2, Clock::now());
  for (std::size_t p = 0; p < producers_.size(); ++p) producers_[p]->solved(static_cast<int>(p), rows_);
  return rep;
}

}  // namespace mannequin::constraints
