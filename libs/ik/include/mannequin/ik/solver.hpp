#pragma once
/// \file solver.hpp
/// \brief Strict-priority inverse kinematics with the three nested loops of the paper (Fig. 6):
///
/// - convergence loop (outer): re-linearise at the current q, ask each task for at most one
///   step's worth of error (StepLimits), apply Δθ, until every level is satisfied, the step
///   vanishes (a least-squares optimum: the lower levels are as close as the higher allow) or
///   max_iterations. Strictness is linear only: far from the linearisation point a lower level's
///   step moves the higher levels at second order. So a step is accepted only if no level ends
///   worse than max(its residual before, its tolerance) while lower levels still contribute;
///   otherwise the contributions of the levels below the first damaged one are halved, and set
///   to zero after max_backtracks halvings (lexicographic backtracking). Damage done by a level's
///   own or higher levels' steps is accepted (it is progress of a higher priority);
/// - clamping loop (middle): solve; any limited coordinate that θ + Δθ would push past its limit
///   is set to the limit (Δθ_i = limit − θ_i), removed from P_0, and the solution recomputed
///   (Baerlocher & Boulic 2004), until no new violation;
/// - priority loop (inner): PriorityLoop (priority.hpp), eq. (6) with (8), or (7) as reference.
///
/// Levels are numbered from 0 (highest priority). Tasks in one level are stacked, each scaled by
/// the square root of its weight. Δθ is in IK coordinates (tasks.hpp): ball joints move their
/// rotation vector, the root moves by its body twist.
#include <memory>
#include <string>
#include <vector>

#include "mannequin/ik/priority.hpp"
#include "mannequin/ik/tasks.hpp"

namespace mannequin::ik {

struct LevelOptions {
  std::string name;
  double damping = 0.0;    ///< λ of this level's damped inverse (paper Annex)
  double tolerance = 1e-4; ///< level satisfied when its residual (‖stacked e‖) ≤ tolerance
};

struct SolverOptions {
  ProjectorUpdate update = ProjectorUpdate::kRecursive;
  double rank_tolerance = 1e-9;  ///< absolute threshold on singular values
  int max_iterations = 100;      ///< convergence loop
  double min_step = 1e-9;        ///< stop when ‖Δθ‖∞ falls below (stalled at an optimum)
  StepLimits step_limits;        ///< error asked per iteration
  bool joint_limits = true;      ///< clamping loop on model.lower_limit/upper_limit
  int max_backtracks = 12;       ///< halvings of a level's contribution before it is dropped
  /// Before halving, re-solve the damaged level and those above it at the trial point and check
  /// again (second-order correction, docs/ik.md).
  bool correction = true;
  /// Converged when, over the last progress_window iterations, no unsatisfied level's residual fell
  /// by more than progress_tolerance × its residual at the window's start, and no satisfied level
  /// was lost (the lower levels are as close as the higher ones allow; the posture may still drift
  /// in the remaining null space). 0 disables the test.
  int progress_window = 20;
  double progress_tolerance = 1e-4;
};

/// Why the convergence loop stopped: every level satisfied; the step vanished (‖Δθ‖∞ < min_step)
/// or no step was accepted; the residuals stopped improving (progress_window); max_iterations.
enum class StopReason { kAllSatisfied, kStalled, kConverged, kMaxIterations };
const char* toString(StopReason r);

struct TaskReport {
  std::string name;
  int level = 0;
  double residual = 0.0;  ///< ‖e‖ at the final q (PostureTask: see PostureTask::residual)
};

struct LevelReport {
  std::string name;
  double residual = 0.0;   ///< ‖stacked unweighted e‖ at the final q
  double tolerance = 0.0;
  bool satisfied = false;
  int satisfied_at = -1;   ///< first iteration at which it was satisfied (−1: never)
  int rank = 0;            ///< rank of Ĵ_k at the last iteration
};

struct SolveReport {
  StopReason stop = StopReason::kMaxIterations;
  int iterations = 0;          ///< convergence-loop iterations (Δθ applied)
  int clamping_passes = 0;     ///< extra priority loops run by the clamping loop, all iterations
  int clamped = 0;             ///< coordinates at a limit after the last iteration's clamping
  int backtracks = 0;          ///< halvings of level contributions, all iterations
  int corrections = 0;         ///< second-order corrections tried, all iterations
  std::vector<LevelReport> levels;
  std::vector<TaskReport> tasks;
  bool allSatisfied() const;
};

class IkSolver {
 public:
  explicit IkSolver(const Model& model, SolverOptions options = {});

  /// Adds a level below the existing ones; returns its index. \throws std::invalid_argument on
  /// a negative/NaN damping or tolerance.
  int addLevel(LevelOptions options);
  /// Adds a task to a level; returns a reference to it (owned by the solver).
  /// \throws std::invalid_argument on an unknown level or a duplicate task name.
  Task& addTask(int level, std::unique_ptr<Task> task);
  template <class T, class... Args>
  T& emplaceTask(int level, Args&&... args) {
    return static_cast<T&>(addTask(level, std::make_unique<T>(std::forward<Args>(args)...)));
  }
  /// Task by name. \throws std::invalid_argument listing the tasks when absent.
  Task& task(const std::string& name);
  int levelCount() const { return static_cast<int>(levels_.size()); }
  const Model& model() const { return model_; }
  SolverOptions& options() { return options_; }

  /// Runs the three loops from q (in/out). On an exception q is unchanged.
  /// \throws std::invalid_argument on a wrong-size or non-finite q.
  SolveReport solve(VectorX& q);

  /// One linearised step at q (priority + clamping loops, errors limited by step_limits):
  /// Δθ in IK coordinates. Exposed for tests and benchmarks.
  const VectorX& step(const VectorX& q);
  /// q ⊕ Δθ (IK coordinates; the root by exp on SE(3)).
  VectorX apply(const VectorX& q, const VectorX& dtheta) const;
  /// Residuals of every level and task at q (no step).
  SolveReport evaluate(const VectorX& q);

  /// The linearised levels of the last step/evaluate (J in IK coordinates, dx = limited errors,
  /// weighted), and the priority loop (its projector, ranks).
  const std::vector<LinearLevel>& linearLevels() const { return linear_; }
  const PriorityLoop& priorityLoop() const { return loop_; }

  /// The clamping loop's state (solver.cpp): P_0 mask and Δθ_0 for the coordinates clamped for
  /// every level, the first level each coordinate is clamped at (−1: free), the other clamps.
  struct ClampState {
    VectorX free, dtheta0, partial;
    std::vector<int> level;
    std::vector<LevelClamp> clamps;
  };

 private:
  struct Level {
    LevelOptions options;
    std::vector<std::unique_ptr<Task>> tasks;
  };
  void linearise(const VectorX& q, bool limit_steps, SolveReport* report);
  int firstDamaged(const SolveReport& before, const SolveReport& trial, const VectorX& alpha) const;
  VectorX applyWithinLimits(const VectorX& q, const VectorX& dtheta) const;
  void checkConfiguration(const VectorX& q) const;

  const Model& model_;
  SolverOptions options_;
  Data data_;
  IkContext ctx_;
  std::vector<Level> levels_;
  std::vector<LinearLevel> linear_;
  PriorityLoop loop_;
  ClampState clamp_, correction_clamp_;
  PriorityLoop correction_loop_;
  std::vector<LinearLevel> head_;  ///< the levels a correction re-solves
  VectorX lower_, upper_;
  std::vector<int> limited_;  ///< coordinates with at least one finite limit (never the root)
};

}  // namespace mannequin::ik
