#include "mannequin/ik/solver.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "mannequin/math/so3.hpp"

namespace mannequin::ik {

using skeleton::JointType;

const char* toString(StopReason r) {
  switch (r) {
    case StopReason::kAllSatisfied: return "all_satisfied";
    case StopReason::kStalled: return "stalled";
    case StopReason::kConverged: return "converged";
    case StopReason::kMaxIterations: return "max_iterations";
  }
  return "?";
}

bool SolveReport::allSatisfied() const {
  for (const auto& l : levels)
    if (!l.satisfied) return false;
  return true;
}

IkSolver::IkSolver(const Model& model, SolverOptions options)
    : model_(model),
      options_(options),
      data_(model),
      ctx_(model, data_),
      loop_(model.nv, PriorityOptions{options.update, options.rank_tolerance, options.step_limits.joint}),
      correction_loop_(model.nv, loop_.options()) {
  if (options.max_iterations < 0) throw std::invalid_argument("IkSolver: max_iterations must be >= 0");
  if (!(options.min_step >= 0.0)) throw std::invalid_argument("IkSolver: min_step must be >= 0");
  if (!(options.progress_tolerance >= 0.0) || options.progress_window < 0)
    throw std::invalid_argument("IkSolver: progress_window and progress_tolerance must be >= 0");
  if (!(options.step_limits.linear > 0.0) || !(options.step_limits.angular > 0.0) ||
      !(options.step_limits.joint > 0.0))
    throw std::invalid_argument("IkSolver: step limits must be > 0");
  for (ClampState* c : {&clamp_, &correction_clamp_}) {
    c->free = VectorX::Ones(model.nv);
    c->dtheta0 = VectorX::Zero(model.nv);
    c->partial = VectorX::Zero(model.nv);
    c->level.assign(static_cast<std::size_t>(model.nv), -1);
  }
  lower_ = model.lower_limit;
  upper_ = model.upper_limit;
  for (const auto& joint : model.joints) {
    if (joint.type == JointType::kFreeFlyer) continue;
    for (int k = 0; k < joint.nq; ++k) {
      const int i = joint.idx_q + k;
      if (std::isfinite(lower_(i)) || std::isfinite(upper_(i))) limited_.push_back(i);
    }
  }
}

int IkSolver::addLevel(LevelOptions options) {
  if (!(options.damping >= 0.0) || !std::isfinite(options.damping))
    throw std::invalid_argument("level '" + options.name + "': damping must be finite and >= 0");
  if (!(options.tolerance >= 0.0))
    throw std::invalid_argument("level '" + options.name + "': tolerance must be >= 0");
  if (options.name.empty()) options.name = "level" + std::to_string(levels_.size());
  levels_.push_back(Level{std::move(options), {}});
  linear_.emplace_back();
  return static_cast<int>(levels_.size()) - 1;
}

Task& IkSolver::addTask(int level, std::unique_ptr<Task> task) {
  if (level < 0 || level >= levelCount())
    throw std::invalid_argument("IkSolver: no level " + std::to_string(level) + " (there are " +
                                std::to_string(levelCount()) + ")");
  if (!task) throw std::invalid_argument("IkSolver: null task");
  for (const auto& l : levels_)
    for (const auto& t : l.tasks)
      if (t->name() == task->name()) throw std::invalid_argument("IkSolver: duplicate task name '" + task->name() + "'");
  levels_[level].tasks.push_back(std::move(task));
  return *levels_[level].tasks.back();
}

Task& IkSolver::task(const std::string& name) {
  std::string names;
  for (auto& l : levels_)
    for (auto& t : l.tasks) {
      if (t->name() == name) return *t;
      names += (names.empty() ? "" : ", ") + t->name();
    }
  throw std::invalid_argument("IkSolver: no task '" + name + "' (tasks: " + names + ")");
}

void IkSolver::checkConfiguration(const VectorX& q) const {
  if (q.size() != model_.nq)
    throw std::invalid_argument("IkSolver: configuration has " + std::to_string(q.size()) + " coordinates, model '" +
                                model_.name + "' has " + std::to_string(model_.nq));
  if (!q.allFinite()) throw std::invalid_argument("IkSolver: non-finite configuration");
}

void IkSolver::linearise(const VectorX& q, bool limit_steps, SolveReport* report) {
  skeleton::computeJointJacobians(model_, data_, q);
  bool com = false;
  for (const auto& l : levels_)
    for (const auto& t : l.tasks) com = com || t->needsCom();
  if (com) skeleton::jacobianCenterOfMass(model_, data_);
  ctx_.setConfiguration(q);
  if (report) {
    report->levels.resize(levels_.size());
    report->tasks.clear();
  }
  for (std::size_t k = 0; k < levels_.size(); ++k) {
    const Level& level = levels_[k];
    int rows = 0;
    for (const auto& t : level.tasks) rows += t->dim();
    LinearLevel& L = linear_[k];
    L.J.resize(rows, model_.nv);
    L.dx.resize(rows);
    L.damping = level.options.damping;
    double sq = 0.0;
    int row = 0;
    for (const auto& t : level.tasks) {
      const int m = t->dim();
      auto J = L.J.middleRows(row, m);
      auto e = L.dx.segment(row, m);
      t->evaluate(ctx_, J, e);
      const double res = t->residual(e);
      sq += res * res;
      if (report) report->tasks.push_back(TaskReport{t->name(), static_cast<int>(k), res});
      if (limit_steps) t->limitStep(e, options_.step_limits);
      if (t->weight() != 1.0) {
        const double s = std::sqrt(t->weight());
        J *= s;
        e *= s;
      }
      row += m;
    }
    if (report) {
      LevelReport& lr = report->levels[k];
      lr.name = level.options.name;
      lr.tolerance = level.options.tolerance;
      lr.residual = std::sqrt(sq);
      lr.satisfied = lr.residual <= lr.tolerance;
    }
  }
}

namespace {
// Clamping loop around the priority loop; returns passes beyond the first. A limited coordinate
// is clamped at the first level k whose partial solution Δθ_k (every level above included) takes
// it past a limit: held at the limit from level k on (k = 0: P_0 and Δθ_0, the paper's clamping;
// k > 0: a LevelClamp), so the levels above k keep it and the backtracking scales the clamp with
// level k. Clamps only move up a level or get added, so the loop ends.
int clampingLoop(PriorityLoop& loop, const std::vector<LinearLevel>& levels, const VectorX& q,
                 const std::vector<int>& limited, const VectorX& lower, const VectorX& upper, bool limits,
                 IkSolver::ClampState& state, int* clamped) {
  VectorX& free = state.free;
  VectorX& dtheta0 = state.dtheta0;
  VectorX& partial = state.partial;
  std::vector<int>& clamp_level = state.level;
  std::vector<LevelClamp>& clamps = state.clamps;
  free.setOnes();
  dtheta0.setZero();
  clamps.clear();
  std::fill(clamp_level.begin(), clamp_level.end(), -1);
  int passes = 0;
  *clamped = 0;
  const int p = static_cast<int>(levels.size());
  const int max_passes = static_cast<int>(limited.size()) * std::max(p, 1) + 1;
  for (int pass = 0; pass < max_passes; ++pass) {
    loop.solve(levels, &free, &dtheta0, &clamps);
    if (!limits) break;
    const MatrixX& C = loop.contributions();
    bool violation = false;
    for (int i : limited) {
      const int current = clamp_level[i] < 0 ? p : clamp_level[i];
      partial(i) = dtheta0(i);
      for (int k = 0; k < current; ++k) {
        partial(i) += C(i, k);
        const double next = q(i) + partial(i);
        constexpr double eps = 1e-12;
        if (next > upper(i) + eps || next < lower(i) - eps) {
          const double target = (next > upper(i) ? upper(i) : lower(i)) - q(i);
          if (clamp_level[i] < 0) ++*clamped;
          clamp_level[i] = k;
          if (k == 0) {
            free(i) = 0.0;
            dtheta0(i) = target;
          } else {
            bool found = false;
            for (auto& c : clamps)
              if (c.coordinate == i) {
                c.level = k;
                c.dtheta = target;
                found = true;
              }
            if (!found) clamps.push_back(LevelClamp{i, k, target});
          }
          violation = true;
          break;
        }
      }
    }
    if (violation) {
      // a coordinate moved to level 0 leaves the per-level list
      std::erase_if(clamps, [&](const LevelClamp& c) { return clamp_level[c.coordinate] == 0; });
    } else {
      break;
    }
    ++passes;
  }
  return passes;
}
}  // namespace

const VectorX& IkSolver::step(const VectorX& q) {
  checkConfiguration(q);
  linearise(q, true, nullptr);
  int clamped = 0;
  clampingLoop(loop_, linear_, q, limited_, lower_, upper_, options_.joint_limits, clamp_, &clamped);
  return loop_.dtheta();
}

VectorX IkSolver::apply(const VectorX& q, const VectorX& dtheta) const {
  VectorX out = q;
  for (const auto& joint : model_.joints) {
    const int i = joint.idx_q;
    switch (joint.type) {
      case JointType::kRevolute: out(i) += dtheta(joint.idx_v); break;
      case JointType::kBall: {
        Vector3 r = q.segment<3>(i) + dtheta.segment<3>(joint.idx_v);
        const double a = r.norm();
        // keep the rotation vector in the ball of radius π (same rotation)
        if (a > std::numbers::pi) r *= (a - 2.0 * std::numbers::pi) / a;
        out.segment<3>(i) = r;
        break;
      }
      case JointType::kFreeFlyer: {
        const SE3 H(math::expSO3(q.segment<3>(i + 3)), q.segment<3>(i));
        const SE3 Hn = H * math::expSE3(dtheta.segment<6>(joint.idx_v));
        out.segment<3>(i) = Hn.p;
        out.segment<3>(i + 3) = math::logSO3(Hn.R);
        break;
      }
    }
  }
  return out;
}

SolveReport IkSolver::evaluate(const VectorX& q) {
  checkConfiguration(q);
  SolveReport report;
  linearise(q, false, &report);
  return report;
}

int IkSolver::firstDamaged(const SolveReport& before, const SolveReport& trial, const VectorX& alpha) const {
  const int p = levelCount();
  for (int k = 0; k < p; ++k) {
    bool lower = false;
    for (int j = k + 1; j < p; ++j) lower = lower || alpha(j) > 0.0;
    if (!lower) return -1;  // damage from its own or higher levels' steps is not a priority violation
    const double b = before.levels[k].residual;
    const double allowed = std::max(b, before.levels[k].tolerance);
    if (trial.levels[k].residual > allowed + 1e-12 * (1.0 + b)) return k;
  }
  return -1;
}

VectorX IkSolver::applyWithinLimits(const VectorX& q, const VectorX& dtheta) const {
  VectorX out = apply(q, dtheta);
  if (options_.joint_limits)
    for (int i : limited_) out(i) = std::clamp(out(i), lower_(i), upper_(i));
  return out;
}

SolveReport IkSolver::solve(VectorX& q) {
  checkConfiguration(q);
  VectorX qk = q;
  SolveReport report, trial, corrected;
  linearise(qk, true, &report);
  const int p = levelCount();
  VectorX alpha(p), d(model_.nv);
  // residuals and satisfied flags of every level, one row per iteration (progress test)
  const int window = std::max(options_.progress_window, 0);
  std::vector<double> history;
  std::vector<char> satisfied_history;
  if (window > 0) {
    history.reserve(static_cast<std::size_t>(p) * (options_.max_iterations + 1));
    satisfied_history.reserve(history.capacity());
  }
  for (int it = 0;; ++it) {
    for (auto& l : report.levels)
      if (l.satisfied && l.satisfied_at < 0) l.satisfied_at = it;
    if (report.allSatisfied()) {
      report.stop = StopReason::kAllSatisfied;
      break;
    }
    if (window > 0) {
      for (const auto& l : report.levels) {
        history.push_back(l.residual);
        satisfied_history.push_back(l.satisfied ? 1 : 0);
      }
      if (it >= window) {
        // compare with the row `window` iterations ago
        const std::size_t then = static_cast<std::size_t>(it - window) * p, now = static_cast<std::size_t>(it) * p;
        bool progress = false;
        for (int k = 0; k < p && !progress; ++k) {
          if (satisfied_history[then + k] && !satisfied_history[now + k]) progress = true;  // lost: not converged
          if (satisfied_history[now + k]) continue;
          progress = history[then + k] - history[now + k] > options_.progress_tolerance * history[then + k];
        }
        if (!progress) {
          report.stop = StopReason::kConverged;
          break;
        }
      }
    }
    if (it >= options_.max_iterations) {
      report.stop = StopReason::kMaxIterations;
      break;
    }
    int clamped = 0;
    report.clamping_passes +=
        clampingLoop(loop_, linear_, qk, limited_, lower_, upper_, options_.joint_limits, clamp_, &clamped);
    report.clamped = clamped;
    for (int k = 0; k < p; ++k) report.levels[k].rank = loop_.ranks()[k];
    const MatrixX& C = loop_.contributions();
    // lexicographic backtracking on the level contributions, with a second-order correction
    alpha.setOnes();
    bool accepted = false;
    for (;;) {
      d = clamp_.dtheta0;
      d.noalias() += C * alpha;
      if (d.lpNorm<Eigen::Infinity>() < options_.min_step) break;
      VectorX q_try = applyWithinLimits(qk, d);
      linearise(q_try, true, &trial);
      // first level made worse while lower levels still contribute: those lower levels did it
      int damaged = firstDamaged(report, trial, alpha);
      if (damaged >= 0 && options_.correction) {
        // the damage is second order: levels 0..damaged alone, re-linearised at q_try, take
        // their own targets back (one Gauss-Newton step of the higher levels, clamping included)
        head_.assign(linear_.begin(), linear_.begin() + damaged + 1);
        int c = 0;
        clampingLoop(correction_loop_, head_, q_try, limited_, lower_, upper_, options_.joint_limits,
                     correction_clamp_, &c);
        VectorX q_corr = applyWithinLimits(q_try, correction_loop_.dtheta());
        linearise(q_corr, true, &corrected);
        ++report.corrections;
        const int still = firstDamaged(report, corrected, alpha);
        if (still < 0) {
          q_try = std::move(q_corr);
          std::swap(trial, corrected);
        }
        damaged = still;
      }
      if (damaged < 0) {
        accepted = true;
        qk = std::move(q_try);
        break;
      }
      ++report.backtracks;
      const double smallest = std::ldexp(1.0, -options_.max_backtracks);
      for (int k = damaged + 1; k < p; ++k) alpha(k) = alpha(k) * 0.5 < smallest ? 0.0 : alpha(k) * 0.5;
    }
    if (!accepted) {
      linearise(qk, true, nullptr);  // restore the linearisation of the kept q
      report.stop = StopReason::kStalled;
      break;
    }
    for (int k = 0; k < p; ++k) report.levels[k].residual = trial.levels[k].residual;
    for (int k = 0; k < p; ++k) report.levels[k].satisfied = trial.levels[k].satisfied;
    report.tasks = trial.tasks;
    ++report.iterations;
  }
  q = qk;
  return report;
}

}  // namespace mannequin::ik
