#pragma once
/// \file config.hpp
/// \brief What a World is built from: the mannequins' setups (MannequinSetup) and the simulation's
/// configuration (SimConfig with its PhysicsConfig and BalanceControllerConfig). Plain data; the sim
/// service reads them from YAML (services/sim/src/config.cpp).
#include <optional>
#include <string>
#include <vector>

#include "mannequin/collision/scene.hpp"
#include "mannequin/constraints/balance.hpp"
#include "mannequin/constraints/contacts.hpp"
#include "mannequin/constraints/joint_limits.hpp"
#include "mannequin/constraints/solver.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/sim/tracker.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::sim {

/// A control frame driven by a mocap body.
struct ControlFrameSpec {
  std::string frame;  ///< model frame (e.g. "hand_l", "palm_l", "pelvis")
  std::string body;   ///< mocap body name
};

struct MannequinSetup {
  std::string name;             ///< instance name in sim.world
  skeleton::Model model;        ///< built from configs/mannequins/*.yaml by the caller
  std::vector<ControlFrameSpec> frames;
  std::string root_frame = "pelvis";  ///< frame whose body places the mannequin at calibration
  /// The mocap source whose bodies drive this mannequin (World::addMocap(frame, source)); "" is the
  /// default source. Two actors captured by two systems: two mannequins with two sources, each with
  /// its own buffer and clock anchor.
  std::string mocap_source;
  /// The controller's config (configs/control/*.yaml): steps the mannequin with a ControllerStepper.
  /// Empty: the KinematicTracker with SimConfig::gains.
  std::optional<control::ControllerConfig> controller;
};

/// The multi-contact balance controller in the loop (thesis 3.96–3.107, Algorithm 5, and 4.4.2).
/// Every `period` s, for each calibrated mannequin: Algorithm 5 at q_k with its touching contacts with
/// the static scene (the points, normals and μ of the step's contact rows; each body in contact held
/// where it is), the driven frames that are neither in contact nor in `frames` as position tasks towards
/// their mocap targets, and the margins below. Its result q_b = q_k ⊕ δq drives the mannequin through
/// couplings, so the loop stays force-based and passive (4.4.2: "a joint controller that generates the
/// torques giving δq"): the targets of the control frames named in `frames` (the pelvis and head of
/// the VR-room set) become their poses at q_b instead of their mocap bodies', every other coordinate is
/// pulled towards q_b by a joint spring-damper (the joint controller 4.4.2 proposes), and q_b is the
/// posture target of the internal control (2.25). The spring-dampers of those couplings carry the body there
/// against gravity; contacts, limits and the other frames act as before. A solve that fails (no
/// equilibrium with these margins: kInfeasible) hands the frames back to their mocap bodies and the
/// posture back to q_c until a later solve succeeds; MannequinDiagnostics says which.
/// Allocates at each solve (like the force margins): off by default.
struct BalanceControllerConfig {
  bool enabled = false;
  double period = 0.01;                     ///< s between solves (rounded to steps, ≥ 1 step)
  std::vector<std::string> frames = {"pelvis", "head"};  ///< driven frames the controller takes over
  /// Pushes (N, world) at the CoM the posture must hold (3.93–3.95), each balanced by non-negative
  /// contact forces at the posture's own CoM (VariationalBalanceProblem::margins_at_com).
  std::vector<math::Vector3> force_margins;
  int edges = 4;                            ///< edges per linearised friction cone (3.56)
  double max_step = 0.02;                   ///< |δq_j| per solve (rad, m): the small-displacement bound
  double max_task_step = 0.01;              ///< m per solve a task moves its frame
  double dq_weight = 1e6;                   ///< w_q of (3.107): 1 mrad of δq weighs as 1 N of edge force
  /// β of the internal control (thesis 4.1): each solve pulls δq towards β (q_c ⊖ q_k), q_c the calibrated
  /// posture, where the equilibrium, held bodies and tasks leave it free. Without it (0) nothing holds
  /// the posture between solves: each starts from where gravity left the body, and it sinks.
  double posture_gain = 0.2;
  /// The joint coupling towards q_b (control::Controller::setJointCoupling) on every coordinate but the
  /// root's (the frames in `frames` place the root): N·m/rad and N·m·s/rad.
  double joint_stiffness = 1000.0;
  double joint_damping = 0.0;
};

/// Physics in the loop (thesis Alg. 4): contacts between the mannequins, the scene and the objects as
/// rows of one LCP per step with the joint limits (and balance, grasps). Needs ControllerSteppers.
struct PhysicsConfig {
  bool enabled = false;
  /// Gravity (m/s², world) of every mannequin's controller when physics is on: the weight comes with
  /// the contacts that carry it (replaces the controller config's `gravity`).
  math::Vector3 gravity = math::Vector3(0, 0, -9.81);
  collision::SceneSpec scene;      ///< static bodies (floor, table ...), materials, μ table
  double segment_margin = 0.005;   ///< margin of every mannequin segment (m)
  std::string segment_material = "skin";
  /// Contacts between the segments of one mannequin (off by default: captured actors pass their hands
  /// through their own trunk models and cross their feet, and those rows then fight the mocap targets).
  bool self_collision = false;
  int query_period_steps = 1;      ///< collision query every N steps (witness points re-evaluated at q_k in between)
  double activation_distance = 0.02;  ///< m: pairs closer than this become rows (the predictive scheme's candidates)
  /// The contact–control paradox (thesis 4.4.3): a foot target calibrated slightly below the floor
  /// would push the sole into it forever. At calibration, targets of frames whose segment touches the
  /// floor are lifted by the sole's calibration depth plus this clearance (m).
  double calibration_clearance = 0.002;
  constraints::ContactOptions contacts;  ///< friction edges, recovery speed (μ from the scene)
  /// Coplanar balance (thesis 3.3.2.1): the support region of each mannequin is rebuilt every step from
  /// its feet's floor contacts (within `foot_contact_tolerance`), and the signed distance of its CoM
  /// projection is in MannequinDiagnostics::balance_distance_m. With `balance_rows` the distance is
  /// also a unilateral row of the step's LCP (the CoM is kept over the support); off by default: a
  /// captured actor's hops and steps leave the support on purpose.
  bool balance_rows = false;
  constraints::BalanceOptions balance;
  double foot_contact_tolerance = 0.005;  ///< m between the margin shells: a foot touching the floor
  /// Stability margin in disturbing forces (thesis 3.93–3.95, libs/balance): every `force_margin_period`
  /// s (0: never), each calibrated mannequin's largest horizontal push at its CoM (±x, ±y) that its
  /// touching contacts with the static scene hold, its CoM where it is (MannequinDiagnostics::force_margin_n,
  /// bisection to 1 N, at most `force_margin_max` N).
  double force_margin_period = 0.0;
  double force_margin_max = 1000.0;
  /// The multi-contact balance controller (libs/balance, Algorithm 5) in the loop.
  BalanceControllerConfig balance_controller;
  /// τ of the scene's objects without a `time_constant` (s; constraints::RigidObject).
  double object_time_constant = 0.05;
  constraints::SolverOptions solver;
};

struct SimConfig {
  double step = 0.001;                 ///< δt (s)
  double interpolation_delay = 0.0;    ///< s behind the newest capture time (live mode smoothing)
  double occlusion_hold = 0.3;         ///< s
  double occlusion_blend = 0.5;        ///< s
  bool calibration_needs_flag = false; ///< calibrate only on frames flagged calibration_pose
  /// Steps of posture fitting at calibration: q_c is first pulled so that every control frame's origin
  /// reaches its body's position (orientations free), from standing; 0 = use the standing posture as is.
  int calibration_fit_steps = 0;
  TrackerGains gains;                  ///< KinematicTracker gains (stepper: kinematic, calibration fit)
  bool target_twist = true;            ///< feed the targets' velocities forward (ControllerStepper)
  double max_target_speed = 10.0;      ///< m/s (and rad/s × 0.3 m): faster target motion is a jump
  /// Joint limits as unilateral constraints in the ControllerStepper (nullopt: off). The kinematic
  /// tracker always clamps to the limits.
  std::optional<constraints::JointLimitOptions> joint_limits = constraints::JointLimitOptions{};
  PhysicsConfig physics;
};

}  // namespace mannequin::sim
