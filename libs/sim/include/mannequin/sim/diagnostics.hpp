#pragma once
/// \file diagnostics.hpp
/// \brief What a World reports after a step (world frame throughout): the step's diagnostics, each
/// mannequin's, the contacts, the grasps, the mocap glitches met and the driven control frames.
#include <cstdint>
#include <limits>
#include <string>

#include "mannequin/balance/static_balance.hpp"
#include "mannequin/constraints/solver.hpp"
#include "mannequin/math/se3.hpp"

namespace mannequin::sim {

/// A grasp held now (World::grasp), for reports.
struct GraspState {
  int handle = -1;     ///< World::grasp's handle
  int mannequin = -1;
  int joint = -1;      ///< joint of the mannequin's model carrying the grasping frame
  int object = -1;     ///< object index
  math::Vector3 force = math::Vector3::Zero();  ///< N, world: on the object at the last step (the hand gets −force)
};

/// One contact after a step's solve, for sim.world and diagnostics (world frame).
struct ContactReport {
  int body_a = -1, body_b = -1;       ///< collision body ids (names: World::collisionWorld().bodyName)
  math::Vector3 point = math::Vector3::Zero();   ///< m, midpoint of the witness points at q_k
  math::Vector3 normal = math::Vector3::UnitZ(); ///< from a to b
  double distance = 0.0;        ///< m, after margins (< 0: the margin shells overlap)
  double normal_force = 0.0;    ///< N
  double friction_force = 0.0;  ///< N
};

/// Per mannequin, after a step.
struct MannequinDiagnostics {
  int contacts = 0;                 ///< contact rows on this mannequin
  bool foot_contact = false;        ///< a foot segment touches the floor (distance ≤ activation, λ > 0 or d ≤ 0)
  double sole_height_m = 0.0;       ///< signed height of the lowest sole point above the floor (real geometry)
  double balance_distance_m = std::numeric_limits<double>::quiet_NaN();  ///< signed (3.22); NaN: no support
  double worst_joint_limit_excess_rad = 0.0;  ///< max over coordinates of how far past a limit (≥ 0)
  math::Vector3 com = math::Vector3::Zero();  ///< centre of mass (world, m) at q_k
  int support_points = 0;           ///< foot–floor contact points of the support region
  /// The largest horizontal push at the CoM (N, any of ±x, ±y) the mannequin's touching contacts with
  /// the static scene hold with its CoM where it is (balance::forceMargin, multi-contact and non-coplanar:
  /// hands on a wall count); 0 when the posture itself has no static equilibrium (in the air, leaning
  /// out); NaN when not evaluated (PhysicsConfig::force_margin_period 0, or not calibrated). Kept
  /// between evaluations.
  double force_margin_n = std::numeric_limits<double>::quiet_NaN();
  int force_margin_contacts = 0;    ///< touching contact points the last evaluation used
  /// The balance controller (PhysicsConfig::balance_controller): the outcome of its last solve
  /// (kInvalid before the first), whether its result drives the mannequin now, its solves and failures.
  balance::BalanceStatus balance_status = balance::BalanceStatus::kInvalid;
  bool balance_driving = false;
  int balance_contacts = 0;         ///< contact points of the last solve
  /// Of the force margins asked for, the fraction the last solve held (1: all; the controller grows it
  /// step by step, BalanceControllerConfig); 0 after a failure.
  double balance_margin_fraction = 0.0;
  /// The last solve left the tasks out: with them its equality rows were dependent (a hand task whose
  /// forearm is held on a wall).
  bool balance_tasks_dropped = false;
  math::Vector3 balance_com = math::Vector3::Zero();  ///< the controller's CoM (world, m): at q_b, linearised
  long balance_solves = 0, balance_failures = 0;  ///< solves (every margin fraction tried), failed updates
};

/// What the last step did (thesis Alg. 4 stages), for callers and sim.world.
struct StepDiagnostics {
  int contacts = 0;                  ///< contact rows
  int active_contacts = 0;           ///< with λ > 0
  double max_penetration_m = 0.0;    ///< deepest penetration of the real geometry (margins excluded), ≥ 0
  int failed_collision_pairs = 0;    ///< pairs of this step's collision query (if any) whose narrow phase failed (no contact)
  constraints::SolveReport solver;   ///< rows, LCP size, solver used, pivots, fallback
  bool nan = false;                  ///< a mannequin step produced non-finite numbers (state kept)
  double collision_s = 0, free_motion_s = 0, constraints_s = 0, integrate_s = 0;  ///< wall time per stage
};

/// Mocap glitches the World met, counted per kind over its life (all sources); sim.world carries them
/// (`mocap_glitches`), docs/cluster.md "Faults".
struct MocapGlitches {
  std::uint64_t duplicate_frames = 0;     ///< a frame with its source's newest capture time: ignored
  std::uint64_t out_of_order_frames = 0;  ///< a frame older than the newest, by at most the buffer window: ignored
  /// A frame older than the newest by more than the buffer window (2 s): a restarted capture clock (a
  /// restarted mocap service); the source's buffer starts again from it and, anchored, is re-anchored.
  std::uint64_t capture_restarts = 0;
  std::uint64_t non_finite_bodies = 0;    ///< tracked bodies with a NaN/inf pose: taken as untracked
  /// Tracked bodies farther from their last tracked position than `max_target_speed` m/s × the time
  /// since (+ 5 cm): a marker swap, taken as untracked (held) until the elapsed time allows the distance.
  /// Not when every tracked body of the frame jumps (the actor relocated, a looping capture's wrap): taken as is.
  std::uint64_t pose_jumps = 0;
  std::uint64_t occlusions = 0;           ///< a driven body went from tracked to untracked
  /// Steps where a driven frame's target position moved faster than `max_target_speed` m/s (a 2 m marker
  /// swap, a re-tracked body, a re-anchored clock; fast real motion of a hand body's offset too): its
  /// twist is not fed forward.
  std::uint64_t target_jumps = 0;
  /// A source's newest frame got older than `occlusion_hold` at its capture time (the stream stopped: a
  /// mocap service died, a network gap). Its bodies keep their last targets at full weight (the whole
  /// actor held: blending every frame out let the mannequin sag). When frames come back, each target keeps
  /// the offset it then has to its body, shrinking at 1 m/s (and 3.3 rad/s): it catches up without a jump.
  std::uint64_t stream_gaps = 0;
};

/// A control frame driven by a mocap body, after a step: the World's calibration (bMf), the target it
/// derives from the body, and how well the mannequin follows it. The controller's coupling on the same
/// frame (gains, wrench, port energy) is control::ControlFrameState. The wire's v1::ControlFrameState is
/// filled from this.
struct DrivenFrame {
  std::string frame, body;
  int frame_index = -1;
  math::SE3 offset;         ///< bMf from calibration
  math::SE3 target;         ///< world
  math::SE3 actual;         ///< world
  bool tracked = false;
  double weight = 0.0;
  double position_error = 0.0;     ///< m
  double orientation_error = 0.0;  ///< rad
  /// Its command mode (scenario::toString of scenario::ControlMode): "free" unless a scenario commands it.
  const char* mode = "free";
};

}  // namespace mannequin::sim
