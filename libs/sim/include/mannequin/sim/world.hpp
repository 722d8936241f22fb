#pragma once
/// \file world.hpp
/// \brief The simulated world the sim service steps: mannequins driven by calibrated mocap bodies.
///
/// A World is its constant WorldModel (world_model.hpp: mannequins, control frames, sources, config,
/// physics scene; built and checked once by buildWorldModel) and the WorldData its steps change.
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
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mannequin/collision/world.hpp"
#include "mannequin/kinetics/kinetics.hpp"
#include "mannequin/sim/checkpoint.hpp"
#include "mannequin/sim/config.hpp"
#include "mannequin/sim/diagnostics.hpp"
#include "mannequin/sim/mocap_buffer.hpp"
#include "mannequin/sim/object_guides.hpp"
#include "mannequin/constraints/objects.hpp"
#include "mannequin/sim/stepper.hpp"
#include "mannequin/sim/world_model.hpp"

namespace mannequin::scenario {
class Engine;
struct Scenario;
}  // namespace mannequin::scenario

namespace mannequin::sim {

struct WorldData;  // src/world_state.hpp

class World {
 public:
  /// \throws std::invalid_argument naming an unknown frame (with the model's frames), a step <= 0,
  /// or two mannequins with the same name.
  World(std::vector<MannequinSetup> mannequins, const SimConfig& config);
  /// A World of a model buildWorldModel() built (it builds the steppers and, with physics, the scene).
  /// \throws std::invalid_argument naming the mannequin whose controller config its controller refuses,
  /// or a scene object that cannot be built.
  explicit World(WorldModel model);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;
  World(World&&) = delete;
  World& operator=(World&&) = delete;

  /// The World's constant description (its mannequins, sources, config and physics scene).
  const WorldModel& worldModel() const { return model_; }

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

  double time() const { return static_cast<double>(stepCount()) * model_.config.step; }
  std::uint64_t stepCount() const;
  const SimConfig& config() const { return model_.config; }
  int numMannequins() const { return static_cast<int>(model_.mannequins.size()); }
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
  std::uint64_t failedSteps() const;
  /// The mocap glitches met so far (MocapGlitches).
  const MocapGlitches& mocapGlitches() const;

  //---- physics (PhysicsConfig::enabled) ----
  bool physics() const { return model_.config.physics.enabled; }
  /// The collision world of the physics (scene, mannequin segments, objects); nullptr when off.
  const collision::CollisionWorld* collisionWorld() const;
  const StepDiagnostics& diagnostics() const;
  const MannequinDiagnostics& mannequinDiagnostics(int m) const;
  /// The balance controller's configuration q_b of mannequin m (PhysicsConfig::balance_controller),
  /// nullptr while it does not drive the mannequin.
  const skeleton::VectorX* balanceConfiguration(int m) const;
  /// Contacts of the last step (empty when physics is off).
  const std::vector<ContactReport>& contacts() const;
  /// The constraint solver (nullptr when physics is off).
  const constraints::ConstraintSolver* constraintSolver() const;

  //---- objects of the physics scene (movable bodies with a mass) and grasps ----
  int numObjects() const;
  /// \throws std::out_of_range
  const constraints::RigidObject& object(int i) const;
  /// For pushes (constraints::RigidObject::addForce) and resets between steps.
  constraints::RigidObject& object(int i);
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
  /// The inputs of mannequin m's whole-body kinetics (libs/kinetics) at the last step: `contacts`, each
  /// touching contact on one of its segments (λ > 0 or penetrating) as a point with the normal the other
  /// body pushes it along, the pair's μ and the segment's joint; `loads`, the pull of each object it holds
  /// (−grasp force) at the origin of the grasping joint. Both cleared first; empty with physics off.
  void kineticsInputs(int m, std::vector<kinetics::ContactPoint>& contacts, std::vector<kinetics::Load>& loads) const;
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
  // The stages of step() and their helpers, each in the source file named (libs/sim/src); the state
  // they change is data_ (WorldData, src/world_state.hpp).
  //---- mocap input (mocap_input.cpp) ----
  /// Index of the mocap source `name` in model_.sources, −1 if none.
  int findSource(const std::string& name) const { return model_.findSource(name); }
  /// captureTimeNs of the source with index `source` in model_.sources (the stages know it: no lookup by name).
  std::int64_t sourceCaptureTimeNs(std::size_t source) const;
  /// Stage: counts the sources whose newest frame got older than occlusion_hold (MocapGlitches::stream_gaps).
  void detectStreamGaps();
  //---- calibration (calibration.cpp) ----
  void calibrate(std::size_t m, const mocap::Frame& frame);
  /// Distance after margins of mannequin m's lowest sole to the floor at q (m; +inf: no floor).
  double soleGap(std::size_t m, const skeleton::VectorX& q);
  //---- targets (drive_targets.cpp) ----
  /// Stage: the targets of mannequin m's control frames from their mocap bodies at the capture time of this step.
  void driveTargets(std::size_t m, double dt);
  math::Vector6 targetTwist(std::size_t m, std::size_t i, double dt);
  //---- the scenario (scenario_binding.cpp) ----
  /// Stage: the scenario engine's step; its setpoints replace the commanded frames' targets.
  void stepScenario();
  //---- physics (physics_scene.cpp, physics_step.cpp) ----
  void buildPhysics();
  /// The physics stages: computeFreeMotion, updateContacts, updateSupport, the LCP, integrate, then
  /// computeDiagnostics and the periodic balance stages. Returns false if a mannequin's step failed.
  bool physicsStep();
  /// Stage 1 (thesis Alg. 4): every mannequin's and object's free motion at q_k.
  bool computeFreeMotion();
  /// Contacts at q_k: a collision query every query_period_steps (grasped pairs removed) into the contact rows.
  void updateContacts();
  /// Stage 3: integration of the solved velocities, kinematics at q_{k+1}.
  bool integrate();
  /// Without physics: each mannequin's stepper alone.
  bool kinematicStep();
  //---- diagnostics (diagnostics.cpp) ----
  /// The step's contacts as reports and each mannequin's diagnostics (contacts as solved at q_k).
  void computeDiagnostics();
  /// Each driven frame's pose at q_{k+1} and its errors to its target.
  void updateFrameErrors();
  //---- balance (balance_loop.cpp) ----
  void updateSupport();
  void updateForceMargins();
  void updateBalanceController();
  /// Stage: the frames the balance controller took over get their poses at q_b as targets.
  void applyBalanceTargets(std::size_t m);

  const WorldModel model_;            // the controllers hold references into it: a World is not moved
  std::unique_ptr<WorldData> data_;
};

}  // namespace mannequin::sim
