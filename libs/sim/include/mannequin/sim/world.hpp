#pragma once
/// \file world.hpp
/// \brief The simulated world the sim service steps: mannequins driven by calibrated mocap bodies.
///
/// Time: the World steps by a fixed δt (SimConfig::step). Its clock is tied to the capture clock of the
/// mocap stream by anchor(): capture time = anchor capture time + (World time − anchor World time) −
/// interpolation_delay. Targets are sampled from the MocapBuffer at that capture time.
///
/// Calibration (thesis Fig. 1.10): at the first frame where every body driving a mannequin is tracked
/// and (if `calibration_needs_flag`) the frame is flagged as the calibration pose, the mannequin is put
/// in its calibration configuration q_c (standing, root moved horizontally under the body driving the
/// root frame, then fitted for `calibration_fit_steps` tracker steps so that every control frame's origin
/// reaches its body's position) and each control frame f driven by body b keeps the offset
/// bMf = oMb(c)⁻¹ · oMf(q_c); q_c is also the posture target;
/// afterwards its target is oMd(t) = oMb(t) · bMf (world frame), and its target twist (when
/// `target_twist` is on) the body twist of two consecutive targets, V_d = (log(R_{k−1}ᵀR_k), R_kᵀ(p_k −
/// p_{k−1}))/δt, set to zero when it exceeds `max_target_speed` (a jump, not a motion).
///
/// Stepping: each mannequin has a Stepper (stepper.hpp): a control::Controller when its setup carries
/// a controller config (ControllerStepper, the default of the sim service), else the KinematicTracker.
/// The calibration fit always uses a KinematicTracker (it is an inverse-kinematics problem).
///
/// Occlusion policy (per control frame): while its body is untracked the target holds the last
/// tracked pose for `occlusion_hold` s, then the frame's weight decreases linearly to 0 over
/// `occlusion_blend` s, so the posture control takes the limb back to the posture target; when the body
/// is tracked again the weight rises back to 1 over `occlusion_blend` s (no jump).
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/balance/static_balance.hpp"
#include "mannequin/collision/scene.hpp"
#include "mannequin/collision/world.hpp"
#include "mannequin/constraints/balance.hpp"
#include "mannequin/constraints/contacts.hpp"
#include "mannequin/constraints/joint_limits.hpp"
#include "mannequin/constraints/solver.hpp"
#include "mannequin/sim/mocap_buffer.hpp"
#include "mannequin/control/config.hpp"
#include "mannequin/sim/object_guides.hpp"
#include "mannequin/sim/rigid_object.hpp"
#include "mannequin/sim/stepper.hpp"
#include "mannequin/sim/tracker.hpp"
#include "mannequin/skeleton/model.hpp"

namespace mannequin::scenario {
class Engine;
struct Scenario;
}  // namespace mannequin::scenario

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
  /// τ of the scene's objects without a `time_constant` (s; sim::RigidObject).
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

/// A World's state as a restarted sim puts it back (World::checkpoint, World::restore; the sim service
/// keeps one in its checkpoint file, simservice/checkpoint.hpp). Velocities are not part of it: what is
/// restored starts at rest.
struct MannequinCheckpoint {
  std::string name;                 ///< instance name
  std::string model;                ///< skeleton::Model::name (a restore into another model is refused)
  skeleton::VectorX q;              ///< configuration (nq): root (p, rotation vector) then joints
  bool calibrated = false;
  skeleton::VectorX q_posture;      ///< q_c, the posture target set at calibration (nq; calibrated only)
  /// A driven control frame's calibration (calibrated only; every driven frame, any order).
  struct Frame {
    std::string frame, body;
    math::SE3 offset;               ///< bMf
    math::SE3 target;               ///< world: the last target (held until the mocap drives it again)
    double weight = 1.0;            ///< in [0, 1]
  };
  std::vector<Frame> frames;
};

/// A movable object's pose (PhysicsConfig scene objects).
struct ObjectCheckpoint {
  std::string name;
  bool hinged = false;
  math::SE3 pose;                   ///< world (free body)
  double angle = 0.0;               ///< rad (hinged)
};

struct WorldCheckpoint {
  std::uint64_t step = 0;           ///< step count (the World's time = step · δt)
  std::vector<MannequinCheckpoint> mannequins;  ///< every mannequin of the World, any order
  std::vector<ObjectCheckpoint> objects;        ///< every object of the World, any order
};

class World {
 public:
  /// \throws std::invalid_argument naming an unknown frame (with the model's frames), a step <= 0,
  /// or two mannequins with the same name.
  World(std::vector<MannequinSetup> mannequins, const SimConfig& config);
  ~World();

  /// Adds a mocap frame of `source` (ignored if not newer than that source's last, unless it is older by
  /// more than the buffer window: a restarted capture clock, MocapGlitches::capture_restarts). Tracked
  /// bodies with a non-finite pose are taken as untracked. Calibrates the mannequins it drives when
  /// possible. Returns false for a frame ignored or a source no mannequin uses.
  bool addMocap(const mocap::Frame& frame, const std::string& source = "");
  /// Ties the World clock to a source's capture clock: now, that source's capture time is `capture_ns`.
  /// Again (a re-anchor: the clocks drifted, frames came in a burst): the targets jump in capture time, so
  /// they catch up with their bodies at 1 m/s as after a stream gap (MocapGlitches::stream_gaps).
  void anchor(std::int64_t capture_ns, const std::string& source = "");
  bool anchored(const std::string& source = "") const;
  /// Capture time (ns) of `source` the next step samples targets at.
  std::int64_t captureTimeNs(const std::string& source = "") const;
  /// The mocap sources the mannequins use ("" first).
  std::vector<std::string> mocapSources() const;
  /// One fixed step. Returns false if a mannequin's step failed numerically (its state is kept).
  bool step();

  //---- checkpoint / restore (a restarted sim resuming where it was) ----
  /// The state restore() puts back.
  WorldCheckpoint checkpoint() const;
  /// Puts a checkpoint back: the step count (time), every mannequin's configuration and calibration
  /// (q_c as posture target, every driven frame's offset bMf, last target and weight), every object's
  /// pose. Velocities start at zero, mocap sources unanchored (their next frame anchors them).
  /// Until then a restored calibrated mannequin holds its restored targets. Not restored: grasps, object
  /// guides, the scenario's state (a checkpoint does not hold them: simservice/checkpoint.hpp says so in
  /// its log); the balance controller starts again from q (a note in the returned list when it drove).
  /// \throws std::invalid_argument, the World unchanged, naming the first mismatch: another set of
  /// mannequins or objects, another model, a size, a non-finite number, another set of driven frames.
  std::vector<std::string> restore(const WorldCheckpoint& checkpoint);

  double time() const { return static_cast<double>(steps_) * config_.step; }
  std::uint64_t stepCount() const { return steps_; }
  const SimConfig& config() const { return config_; }
  int numMannequins() const { return static_cast<int>(mannequins_.size()); }
  const std::string& name(int m) const;
  const skeleton::Model& model(int m) const;
  const skeleton::Data& data(int m) const;      ///< kinematics at q (oMi, oMf, com after step)
  const skeleton::VectorX& q(int m) const;
  const skeleton::VectorX& qdot(int m) const;
  bool calibrated(int m) const;
  /// The mannequin's stepper (kind(), and for a ControllerStepper its controller).
  const Stepper& stepper(int m) const;
  const std::vector<DrivenFrame>& controlFrames(int m) const;
  /// The newest mocap frame added to `source` (nullptr before any, or an unknown source).
  const mocap::Frame* latestMocap(const std::string& source = "") const;
  std::uint64_t failedSteps() const { return failed_steps_; }
  /// The mocap glitches met so far (MocapGlitches).
  const MocapGlitches& mocapGlitches() const { return glitches_; }

  //---- physics (PhysicsConfig::enabled) ----
  bool physics() const { return config_.physics.enabled; }
  /// The collision world of the physics (scene, mannequin segments, objects); nullptr when off.
  const collision::CollisionWorld* collisionWorld() const;
  const StepDiagnostics& diagnostics() const { return diagnostics_; }
  const MannequinDiagnostics& mannequinDiagnostics(int m) const;
  /// The balance controller's configuration q_b of mannequin m (PhysicsConfig::balance_controller),
  /// nullptr while it does not drive the mannequin.
  const skeleton::VectorX* balanceConfiguration(int m) const;
  /// Contacts of the last step (empty when physics is off).
  const std::vector<ContactReport>& contacts() const { return contacts_; }
  /// The constraint solver (nullptr when physics is off).
  const constraints::ConstraintSolver* constraintSolver() const;

  //---- objects of the physics scene (movable bodies with a mass) and grasps ----
  int numObjects() const;
  /// \throws std::out_of_range
  const RigidObject& object(int i) const;
  /// For pushes (RigidObject::addForce) and resets between steps.
  RigidObject& object(int i);
  /// Index of the object named `name`, −1 if none.
  int findObject(const std::string& name) const;
  /// Collision body id of object i.
  int objectBody(int i) const;
  /// Runs a scenario's state machine in the loop (thesis 4.1.2, libs/scenario): every step, once all its
  /// mannequins are calibrated, its engine sees the commanded control frames (simulated pose, mocap target;
  /// force: the normal forces of the last step's contacts on the segments the frame carries — its own and
  /// those below it up to the next control frame, e.g. a foot's toes — plus the pull of an object it grasps) and its objects (pose; the value `angle` of a hinged object),
  /// and its setpoints replace those frames' targets — free: the mocap target; constrained: projected on
  /// the mechanism; autonomous: the trajectory — velocity-continuous across switches (their world twist
  /// fed forward as the targets' body twist); a constrained mode also runs its virtual mechanism in the
  /// controller (ControllerStepper::setMechanism, from the switch until the mode changes). Its grasp/release
  /// actions call grasp()/release() (physics on), set_gains ControllerStepper::setGains, attach_guide /
  /// detach_guide attachGuide()/detachGuide(); set_gains with the kinematic stepper is counted in
  /// scenarioUnappliedActions(), not applied.
  /// \throws std::invalid_argument naming a mannequin, frame, object or value the World lacks, or a guide
  /// an object cannot take (GuideRows::supports; a hinged object).
  /// A scenario set while another runs replaces it: the old one's mechanisms are disabled, its grasps
  /// released, its guides detached and its frames' modes set back to free (gains its set_gains changed stay).
  void setScenario(scenario::Scenario s);
  /// An operator trigger, seen by the scenario at the next step; dropped while the scenario does not run
  /// yet (its mannequins not calibrated).
  void trigger(const std::string& name, const std::string& value = "");
  /// The engine (state, time in state, context stack), nullptr without a scenario.
  const scenario::Engine* scenarioEngine() const;
  long scenarioUnappliedActions() const;
  /// Grasps object `object` with the body carrying `frame` of mannequin `m` (e.g. "palm_l", "hand_r") at
  /// their current relative pose (thesis 4.3.1: bilateral rows until release). Contacts between the
  /// object and that mannequin's segments are ignored while held. Returns a handle ≥ 0, or −1 when the
  /// object is already held by this frame's body or every grasp slot is used.
  /// \throws std::invalid_argument naming an unknown mannequin, frame or object, or physics off.
  int grasp(int m, const std::string& frame, const std::string& object);
  /// Releases a grasp; false for an unknown handle.
  bool release(int handle);
  /// Whether a hand holds object i.
  bool objectHeld(int i) const;
  /// Force (N, world) the grasp `handle` applied on its object at the last step (the hand gets the
  /// opposite); zero for an unknown handle.
  math::Vector3 graspForce(int handle) const;
  /// The grasps held now, by handle (empty with physics off).
  std::vector<GraspState> grasps() const;
  /// Force (N, world) on each hand of mannequin m at the last step, [left, right]: the pull of what it
  /// holds (−force of every grasp whose frame is carried by the joint of the segment "hand_l" / "hand_r")
  /// plus the contacts on that segment, each as its normal force along the contact normal (friction,
  /// reported as a magnitude only, is left out). Zero with physics off or without such a segment.
  std::array<math::Vector3, 2> handForces(int m) const;
  /// Guides object i on a virtual mechanism (object_guides.hpp: rows of the LCP on the object alone,
  /// thesis 4.3.1: a tray kept level, a part kept on an axis), replacing a guide it had.
  /// \throws std::invalid_argument on physics off, an unknown object, a hinged object or a spec
  /// GuideRows::supports refuses (a curve, coordinate forces, bad stops), naming the object and why.
  void attachGuide(int i, const control::MechanismSpec& spec);
  /// Ends object i's guide; false if it had none (or physics is off).
  bool detachGuide(int i);
  /// Object i's guide (nullptr with physics off or without objects): its coordinates, errors and force.
  const GuideRows* guides() const;

 private:
  struct Mannequin;
  struct Physics;
  struct Source;
  Source* findSource(const std::string& name);
  const Source* findSource(const std::string& name) const;
  void calibrate(Mannequin& m, const mocap::Frame& frame);
  void updateForceMargins();
  void updateBalanceController();
  void applyBalanceTargets(std::size_t m);
  void updateSupport();
  void fillDiagnostics();
  void buildPhysics();
  /// Distance after margins of mannequin m's lowest sole to the floor at q (m; +inf: no floor).
  double soleGap(Mannequin& m, const skeleton::VectorX& q);
  void driveTargets(Mannequin& m, double dt);
  bool physicsStep();
  math::Vector6 targetTwist(Mannequin& m, std::size_t i, double dt) const;
  std::vector<std::unique_ptr<Mannequin>> mannequins_;
  SimConfig config_;
  std::vector<std::unique_ptr<Source>> sources_;  // "" first
  std::uint64_t steps_ = 0, failed_steps_ = 0;
  MocapGlitches glitches_;
  std::vector<std::size_t> jumps_;  // addMocap: the bodies of a frame that jumped (kept: no allocation per frame)
  struct ScenarioRun;
  std::unique_ptr<ScenarioRun> scenario_;
  void stepScenario();
  std::unique_ptr<Physics> physics_;
  StepDiagnostics diagnostics_;
  std::vector<MannequinDiagnostics> mannequin_diagnostics_;
  std::vector<ContactReport> contacts_;
};

}  // namespace mannequin::sim
